#!/usr/bin/env bash
# The operator page's 3-D view with a 10 M-point map (issue 8): frame times with the level of
# detail against drawing every point. Usage: tests/bench/page_bench.sh [MILLION_POINTS] [FRAMES]
# after `make build` (Debian chromium, playwright-core from web/node_modules). One JSON line.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$src/tests/bench/node_bench_env.sh"
export SCANPLAN_TEST_DOMAIN=${SCANPLAN_TEST_DOMAIN:-201}
exec node "$src/tests/bench/page_bench.mjs" "${1:-10}" "${2:-8}"

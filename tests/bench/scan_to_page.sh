#!/usr/bin/env bash
# From a scan's end to its new candidates visible in the operator's page (Debian chromium), with
# the server's own scan → plan time as the baseline. Usage: tests/bench/scan_to_page.sh [SCANS]
# [ROBOTS] after `make build`. One JSON line.
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$src/tests/bench/node_bench_env.sh"
export SCANPLAN_TEST_DOMAIN=${SCANPLAN_TEST_DOMAIN:-202}
exec node "$src/tests/bench/scan_to_page.mjs" "${1:-15}" "${2:-1}"

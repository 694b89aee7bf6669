#!/usr/bin/env bash
# The server under hostile clients (issue 16): a normal client's request latency and the
# server's memory with HOSTILE connections (default 600) open against it, beside the same client
# on a quiet server in the same run. Usage: tests/bench/hostile_bench.sh [HOSTILE] after
# `make build`. Prints one JSON line (tests/bench/hostile_bench.mjs).
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$src/tests/bench/node_bench_env.sh"
export SCANPLAN_TEST_DOMAIN=${SCANPLAN_TEST_DOMAIN:-201}
exec node "$src/tests/bench/hostile_bench.mjs" "${1:-600}"

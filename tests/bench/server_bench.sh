#!/usr/bin/env bash
# The server under a 30-scan campus session (issue 7): latency from a scan's upload to new
# candidates on the WebSocket, and resident memory. Usage: tests/bench/server_bench.sh [SCANS]
# after `make build`. Prints one JSON line (tests/bench/server_bench.mjs). `server_bench.sh 200 long`:
# the long session (places scanned again pass after pass, no whole-map requests).
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
. "$src/tests/bench/node_bench_env.sh"
export SCANPLAN_TEST_DOMAIN=${SCANPLAN_TEST_DOMAIN:-200}
exec node "$src/tests/bench/server_bench.mjs" "${1:-30}" "${2:-}"

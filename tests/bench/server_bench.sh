#!/usr/bin/env bash
# The server under a 30-scan campus session (issue 7): latency from a scan's upload to new
# candidates on the WebSocket, and resident memory. Usage: tests/bench/server_bench.sh [SCANS]
# after `make build`. Prints one JSON line (tests/bench/server_bench.mjs).
set -euo pipefail
src=$(cd "$(dirname "$0")/../.." && pwd)
build=${BUILD:-$src/build}
export SCANPLAN_SOURCE_DIR=$src
export SCANPLAN_SERVER=$build/server/scanplan-server
export SCANPLAN_BRIDGE=$build/scanner_bridge/scanplan-bridge
export SCANPLAN_CLI=$build/server/scanplan
export SCANPLAN_WEB_DIR=$src/web/dist
export SCANPLAN_TEST_DOMAIN=${SCANPLAN_TEST_DOMAIN:-61}
exec node "$src/tests/bench/server_bench.mjs" "${1:-30}"

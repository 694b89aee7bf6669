# Sourced by the node benchmarks' launchers: where the built programs and the page are, as
# tests/support/stack.mjs expects them. Needs $src (the repository) and optionally $BUILD.
build=${BUILD:-$src/build}
export SCANPLAN_SOURCE_DIR=$src
export SCANPLAN_SERVER=$build/server/scanplan-server
export SCANPLAN_BRIDGE=$build/scanner_bridge/scanplan-bridge
export SCANPLAN_CLI=$build/server/scanplan
export SCANPLAN_WEB_DIR=$src/web/dist

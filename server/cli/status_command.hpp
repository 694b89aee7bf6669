#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan status --server URL [--token T] [--json]`: the session at a glance (scans, points,
// areas, robots and their state, the bridge connection, the current scan's progress, the last
// scan and its correction by matching); with --json the server's GET /api/v1/session answer.
void add_status_command(CLI::App& app);

}  // namespace scanplan::cli

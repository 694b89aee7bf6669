#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan candidates --server URL [--token T] [--json] [--width N --height N | --no-map]`:
// the planner's ranked next scan points as a table and an ASCII top view of the target region
// (regions, scan points, robots, candidates by rank); with --json the server's
// GET /api/v1/candidates answer.
void add_candidates_command(CLI::App& app);

}  // namespace scanplan::cli

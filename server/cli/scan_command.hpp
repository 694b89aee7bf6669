#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan scan`: one simulated scan to a PLY file (DESIGN.md "CLI").
void add_scan_command(CLI::App& app);

}  // namespace scanplan::cli

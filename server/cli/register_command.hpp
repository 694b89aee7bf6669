#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan register`: matches two scans and prints the transform as JSON (DESIGN.md "CLI").
void add_register_command(CLI::App& app);

}  // namespace scanplan::cli

#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan simulate`: the closed loop on a world without DDS (DESIGN.md "CLI").
void add_simulate_command(CLI::App& app);

}  // namespace scanplan::cli

#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan replay FILE.json --server URL`: runs a REST replay script (DESIGN.md "REST replay
// script"): each step's request, checked against its expectations.
void add_replay_command(CLI::App& app);

}  // namespace scanplan::cli

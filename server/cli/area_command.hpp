#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan area`: the terminal operator's view of the mission's area — the target region being
// mapped and the no-go zones no robot is sent into — and setting them (PUT /api/v1/params).
void add_area_command(CLI::App& app);

}  // namespace scanplan::cli

#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan approve ID` and `scanplan reject ID` (--server URL --token T [--by NAME] [--yes]
// [--json]; reject also [--reason TEXT]): POST /api/v1/candidates/{id}/approve|reject with the
// operator token. On a terminal the candidate is shown and confirmation asked first, unless
// --yes; an approval sends the robot off, which is not undone by a keystroke.
void add_decision_commands(CLI::App& app);

}  // namespace scanplan::cli

#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// What the terminal operator does besides deciding on candidates (issue 18), as the page does:
// `propose X Y` (the operator's own scan point, POST /api/v1/goals), `annotate KIND X Y`
// (a victim, hazard, blockage or note, POST /api/v1/annotations) and `exclude-scan ID`
// (a scan out of the map, or back with --restore).
void add_operator_actions(CLI::App& app);

}  // namespace scanplan::cli

#pragma once

#include <CLI/CLI.hpp>

namespace scanplan::cli {

// `scanplan export NAME --out FILE`: one of the server's exports for other teams (the map as
// PLY or LAS, the poses as CSV, the annotations as GeoJSON) saved to a file.
void add_export_command(CLI::App& app);

}  // namespace scanplan::cli

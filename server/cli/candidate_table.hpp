#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace scanplan::cli {

// The answer of GET /api/v1/candidates as text: a line about the plan, then a table with rank,
// id, state, x, y, F, the two gain terms of the paper's Eq. 1 (m²: unscanned area that becomes
// seen, low-resolution area that becomes completed), the travel distance over the movable
// region and the matcher's forecast there (the share of the scan predicted on the trusted map,
// "?" where the match is expected to fail, "-" without a forecast); a refused or rejected
// candidate's note follows its row. Throws nlohmann::json's
// exceptions when the answer lacks a documented field.
std::vector<std::string> render_candidate_table(const nlohmann::json& answer);

// One candidate on one line, for watch's summary after plan_done:
// "1. candidate 12 at (12.3, -4.5): F 1234.5, gains U 1000.0 + M 234.5 m2, travel 15.2 m".
std::string describe_candidate(const nlohmann::json& candidate);

}  // namespace scanplan::cli

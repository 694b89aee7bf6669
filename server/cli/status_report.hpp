#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace scanplan::cli {

// `scanplan status` as text, from the server's own answers: GET /api/v1/session, and
// GET /api/v1/scans for the newest scan's correction by scan matching (placed minus estimated
// pose; the REST API keeps no score, the watch's match_done events carry it). Throws
// nlohmann::json's exceptions when an answer lacks a documented field.
std::vector<std::string> render_status(const std::string& server, const nlohmann::json& session,
                                       const nlohmann::json& scans);

}  // namespace scanplan::cli

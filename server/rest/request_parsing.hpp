#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "common/text_fields.hpp"
#include "http/request.hpp"
#include "scanplan/geometry/pose_limits.hpp"

// Reading requests: each function throws http::HttpError 400 naming what is wrong.
namespace scanplan::server::rest {

// A scan id from the query: a whole number >= 0.
std::int64_t query_scan_id(const http::Request& r, const std::string& name);
// A required, finite number from the query string.
double query_number(const http::Request& r, const std::string& name);
// A positive whole number from the path (`what` names it in the message).
std::uint64_t path_id(const std::string& text, const char* what);
// The request body as a JSON object; `shape` tells the client what is expected.
nlohmann::json object_body(const http::Request& request, const char* shape);
// The optional body of a recorded action, {"by": NAME, "reason": TEXT} (either may be left
// out; nothing else): an empty object when there is no body.
nlohmann::json by_and_reason(const http::Request& request);
// body[key] as a number within lo..hi.
double number_in(const nlohmann::json& body, const char* key, double lo, double hi);
// body[key] as a coordinate in metres in the map frame, within ±kMaxCoordinateM.
double coordinate(const nlohmann::json& body, const char* key);
// Who decided, for decisions and goals: "operator", or "operator NAME" when the body names one
// (at most 100 bytes; an empty name counts as none).
std::string decided_by(const nlohmann::json& body);
// body[key] as text checked by text_problem; empty when the body has no such key.
std::string text_in(const nlohmann::json& body, const char* key, std::size_t max_bytes,
                    TextKind kind);
// `text` when it is a robot id (robot_id_problem), else 400.
std::string robot_in(const std::string& text);
// Who acts, recorded as decisions are: "operator", or "operator NAME" for the body's "by"
// (1 to `max_bytes` bytes).
std::string author_of(const nlohmann::json& body, std::size_t max_bytes = 64);

// A reason (a reject's, a scan taken out of the map) is kept in the session and shown to every
// operator: a sentence or two.
inline constexpr std::size_t kMaxReasonBytes = 2000;

// A coordinate beyond this is a unit mistake (millimetres, a GPS longitude in the wrong field),
// not a place: PoseLimits::max_xy_m, the bound on the poses scans come with.
inline constexpr double kMaxCoordinateM = PoseLimits{}.max_xy_m;

}  // namespace scanplan::server::rest

#include "rest/request_parsing.hpp"

#include <charconv>
#include <cmath>
#include <limits>

#include "http/http_error.hpp"

namespace scanplan::server::rest {

using http::HttpError;
using http::Request;
using nlohmann::json;

std::int64_t query_scan_id(const Request& r, const std::string& name) {
  const std::string& v = r.query.at(name);
  std::int64_t id = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), id);
  if (ec != std::errc() || end != v.data() + v.size() || id < 0) {
    throw HttpError(400, "bad_request",
                    "'" + name + "' is a scan id (a whole number ≥ 0), got '" + v + "'");
  }
  return id;
}

double query_number(const Request& r, const std::string& name) {
  const auto it = r.query.find(name);
  if (it == r.query.end()) {
    throw HttpError(400, "bad_request", "query parameter '" + name + "' is required");
  }
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(it->second, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != it->second.size() || !std::isfinite(v)) {
    throw HttpError(
        400, "bad_request",
        "query parameter '" + name + "' must be a finite number, got '" + it->second + "'");
  }
  return v;
}

std::uint64_t path_id(const std::string& text, const char* what) {
  std::uint64_t n = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  // Every id fits a signed 64-bit integer (SQLite's rowid).
  constexpr auto kMax = static_cast<std::uint64_t>(std::numeric_limits<std::int64_t>::max());
  if (ec != std::errc() || end != text.data() + text.size() || n == 0 || n > kMax) {
    throw HttpError(400, "bad_request",
                    std::string(what) + " is a positive whole number, got '" + text + "'");
  }
  return n;
}

json object_body(const Request& request, const char* shape) {
  json body;
  try {
    body = json::parse(request.body);
  } catch (const json::exception& e) {  // parse_error, or out_of_range for a literal like 1e999
    throw HttpError(400, "bad_request",
                    std::string("the body is not valid JSON (") + e.what() + "); " + shape);
  }
  if (!body.is_object()) {
    throw HttpError(400, "bad_request", std::string("the body must be a JSON object: ") + shape);
  }
  return body;
}

double number_in(const json& j, const char* key, double lo, double hi) {
  const json& v = j.at(key);
  if (!v.is_number() || !std::isfinite(v.get<double>()) || v.get<double>() < lo ||
      v.get<double>() > hi) {
    throw HttpError(400, "bad_request",
                    std::string("'") + key + "' must be a number within " + std::to_string(lo) +
                        ".." + std::to_string(hi));
  }
  return v.get<double>();
}

double coordinate(const json& body, const char* key) {
  if (!body.contains(key)) {
    throw HttpError(400, "bad_request",
                    std::string("'") + key + "' is required (metres in the map frame)");
  }
  const json& v = body.at(key);
  // JSON has no NaN; an overflowing literal like 1e999 parses as infinity.
  if (!v.is_number() || !std::isfinite(v.get<double>()) ||
      std::abs(v.get<double>()) > kMaxCoordinateM) {
    throw HttpError(400, "bad_request",
                    std::string("'") + key +
                        "' must be a finite number of metres in the map frame, within ±" +
                        std::to_string(static_cast<long>(kMaxCoordinateM)) + ", got " + v.dump());
  }
  return v.get<double>();
}

std::string decided_by(const json& body) {
  if (body.is_object() && body.contains("by") && body["by"].is_string()) {
    std::string name = body["by"].get<std::string>();
    if (name.size() > 100) {
      throw HttpError(400, "bad_request", "'by' is limited to 100 bytes");
    }
    if (!name.empty()) return "operator " + name;
  }
  return "operator";
}

std::string author_of(const json& body, std::size_t max_bytes) {
  if (!body.is_object() || !body.contains("by")) return "operator";
  const json& by = body.at("by");
  if (!by.is_string() || by.get<std::string>().empty() ||
      by.get<std::string>().size() > max_bytes) {
    throw HttpError(400, "bad_request",
                    "'by' must be a name of 1 to " + std::to_string(max_bytes) + " bytes");
  }
  return "operator " + by.get<std::string>();
}

}  // namespace scanplan::server::rest

#include "rest/request_parsing.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>

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

namespace {

// A plain decimal number: [+-]digits[.digits][(e|E)[+-]digits], at least one digit before the
// exponent. No hex floats, "inf", "nan" or spaces, which strtod would take.
bool is_decimal(std::string_view v) {
  std::size_t i = 0, digits = 0;
  const auto run = [&] {
    std::size_t n = 0;
    while (i < v.size() && v[i] >= '0' && v[i] <= '9') ++i, ++n;
    return n;
  };
  if (i < v.size() && (v[i] == '+' || v[i] == '-')) ++i;
  digits += run();
  if (i < v.size() && v[i] == '.') {
    ++i;
    digits += run();
  }
  if (digits == 0) return false;
  if (i < v.size() && (v[i] == 'e' || v[i] == 'E')) {
    ++i;
    if (i < v.size() && (v[i] == '+' || v[i] == '-')) ++i;
    if (run() == 0) return false;
  }
  return i == v.size();
}

}  // namespace

double query_number(const Request& r, const std::string& name) {
  const auto it = r.query.find(name);
  if (it == r.query.end()) {
    throw HttpError(400, "bad_request", "query parameter '" + name + "' is required");
  }
  const std::string& text = it->second;
  double v = 0;
  const char* begin = text.data() + (text.starts_with('+') ? 1 : 0);
  const auto [end, ec] = std::from_chars(begin, text.data() + text.size(), v);
  if (!is_decimal(text) || ec != std::errc() || end != text.data() + text.size() ||
      !std::isfinite(v)) {
    throw HttpError(400, "bad_request",
                    "query parameter '" + name + "' must be a finite decimal number, got '" +
                        text.substr(0, 64) + "'");
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

json by_and_reason(const Request& request) {
  if (request.body.empty()) return json::object();
  json body =
      object_body(request, "the body, when given, is {\"by\": \"name\", \"reason\": \"...\"}");
  for (const auto& [key, value] : body.items()) {
    if (key != "by" && key != "reason") {
      throw HttpError(400, "bad_request", "unknown field '" + key + "'");
    }
  }
  return body;
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
  if (!j.is_object() || !j.contains(key)) {
    throw HttpError(400, "bad_request", std::string("'") + key + "' is required");
  }
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
  if (body.is_object() && body.contains("by")) {
    if (!body["by"].is_string()) throw HttpError(400, "bad_request", "'by' must be a name");
    std::string name = body["by"].get<std::string>();
    if (const auto why = text_problem(name, "by", 100, TextKind::kLine)) {
      throw HttpError(400, "bad_request", *why);
    }
    if (!name.empty()) return "operator " + name;
  }
  return "operator";
}

std::string text_in(const json& body, const char* key, std::size_t max_bytes, TextKind kind) {
  if (!body.contains(key)) return {};
  if (!body[key].is_string()) {
    throw HttpError(400, "bad_request", std::string("'") + key + "' must be a string");
  }
  std::string text = body[key].get<std::string>();
  if (const auto why = text_problem(text, key, max_bytes, kind)) {
    throw HttpError(400, "bad_request", *why);
  }
  return text;
}

std::string robot_in(const std::string& text) {
  if (const auto why = robot_id_problem(text)) throw HttpError(400, "bad_request", *why);
  return text;
}

std::string author_of(const json& body, std::size_t max_bytes) {
  if (!body.is_object() || !body.contains("by")) return "operator";
  const json& by = body.at("by");
  if (!by.is_string() || by.get<std::string>().empty() ||
      text_problem(by.get<std::string>(), "by", max_bytes, TextKind::kLine)) {
    throw HttpError(
        400, "bad_request",
        "'by' must be a name of 1 to " + std::to_string(max_bytes) + " bytes on one line");
  }
  return "operator " + by.get<std::string>();
}

}  // namespace scanplan::server::rest

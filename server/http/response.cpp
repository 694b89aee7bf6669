#include "http/response.hpp"

#include <array>
#include <chrono>
#include <ctime>
#include <nlohmann/json.hpp>

#include "http/ascii.hpp"
#include "http/status.hpp"

namespace scanplan::http {
namespace {

// IMF-fixdate. Built by hand because strftime's %a and %b follow the process locale.
std::string http_date(std::time_t t) {
  static constexpr std::array<const char*, 7> kDays = {"Sun", "Mon", "Tue", "Wed",
                                                       "Thu", "Fri", "Sat"};
  static constexpr std::array<const char*, 12> kMonths = {"Jan", "Feb", "Mar", "Apr", "May", "Jun",
                                                          "Jul", "Aug", "Sep", "Oct", "Nov", "Dec"};
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%s, %02d %s %04d %02d:%02d:%02d GMT", kDays[tm.tm_wday % 7],
                tm.tm_mday, kMonths[tm.tm_mon % 12], tm.tm_year + 1900, tm.tm_hour, tm.tm_min,
                tm.tm_sec);
  return buf;
}

void append_sanitized_value(std::string& out, std::string_view value) {
  for (char c : value) {
    const auto u = static_cast<unsigned char>(c);
    out.push_back((u < 0x20 && c != '\t') || u == 0x7f ? ' ' : c);
  }
}

bool is_framing_field(std::string_view name) {
  return ascii::iequals(name, "content-length") || ascii::iequals(name, "transfer-encoding");
}

}  // namespace

Response Response::json(int status, const nlohmann::json& j) {
  Response r;
  r.status = status;
  r.body = j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  r.headers.push_back({"Content-Type", "application/json"});
  return r;
}

Response Response::error(int status, std::string_view code, std::string_view message) {
  return json(status, {{"error", {{"code", code}, {"message", message}}}});
}

Response Response::bytes(std::string body, std::string_view content_type) {
  Response r;
  r.body = std::move(body);
  r.headers.push_back({"Content-Type", std::string(content_type)});
  return r;
}

Response Response::shared(std::shared_ptr<const std::string> body, std::string_view content_type) {
  Response r;
  r.shared_body = body ? std::string_view(*body) : std::string_view();
  r.shared_owner = std::move(body);
  r.headers.push_back({"Content-Type", std::string(content_type)});
  return r;
}

Response Response::shared(std::shared_ptr<const std::vector<std::uint8_t>> body,
                          std::string_view content_type) {
  Response r;
  if (body) {
    r.shared_body = std::string_view(reinterpret_cast<const char*>(body->data()), body->size());
  }
  r.shared_owner = std::move(body);
  r.headers.push_back({"Content-Type", std::string(content_type)});
  return r;
}

std::string_view Response::body_bytes() const {
  return shared_owner ? shared_body : std::string_view(body);
}

void Response::set_header(std::string_view name, std::string_view value) {
  std::erase_if(headers, [&](const Header& h) { return ascii::iequals(h.name, name); });
  headers.push_back({std::string(name), std::string(value)});
}

std::optional<std::string_view> Response::header(std::string_view name) const {
  for (const Header& h : headers) {
    if (ascii::iequals(h.name, name)) return std::string_view(h.value);
  }
  return std::nullopt;
}

std::string serialize_head(const Response& response, bool keep_alive) {
  const int status = (response.status >= 100 && response.status <= 999) ? response.status : 500;
  const bool bodyless = status < 200 || status == 204 || status == 304;

  std::string out;
  out.reserve(256);
  out += "HTTP/1.1 ";
  out += std::to_string(status);
  out += ' ';
  out += reason_phrase(status);
  out += "\r\n";

  bool has_date = false;
  for (const Header& h : response.headers) {
    if (!ascii::is_token(h.name) || is_framing_field(h.name)) continue;
    if (!keep_alive && ascii::iequals(h.name, "connection")) continue;
    has_date = has_date || ascii::iequals(h.name, "date");
    out += h.name;
    out += ": ";
    append_sanitized_value(out, h.value);
    out += "\r\n";
  }
  if (!has_date) {
    out += "Date: ";
    out += http_date(std::time(nullptr));
    out += "\r\n";
  }
  if (!bodyless) {
    // A HEAD response announces the length the GET body would have (RFC 9110 §9.3.2).
    out += "Content-Length: ";
    out += std::to_string(response.body_bytes().size());
    out += "\r\n";
  }
  if (!keep_alive) out += "Connection: close\r\n";
  out += "\r\n";
  return out;
}

bool sends_body(const Response& response, bool head_request) {
  const int status = (response.status >= 100 && response.status <= 999) ? response.status : 500;
  return !(status < 200 || status == 204 || status == 304) && !head_request;
}

std::string serialize(const Response& response, bool keep_alive, bool head_request) {
  std::string out = serialize_head(response, keep_alive);
  if (sends_body(response, head_request)) out += response.body_bytes();
  return out;
}

}  // namespace scanplan::http

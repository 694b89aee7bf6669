// What the REST handlers take from a body (server/rest/request_parsing, server/common/
// text_fields): any bytes as a body give values within their bounds or an HttpError, never a
// crash or another exception (which the server would answer with 500).
#include <cmath>
#include <cstdint>
#include <string>

#include "common/text_fields.hpp"
#include "http/http_error.hpp"
#include "rest/request_parsing.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace rest = scanplan::server::rest;
  scanplan::http::Request request;
  request.body.assign(reinterpret_cast<const char*>(data), size);
  request.query["x"] = request.body.substr(0, 40);
  const auto check = [](auto&& f) {
    try {
      f();
    } catch (const scanplan::http::HttpError&) {
    }
  };
  check([&] { (void)rest::query_number(request, "x"); });
  check([&] { (void)rest::query_scan_id(request, "x"); });
  check([&] { (void)rest::robot_in(request.query["x"]); });
  nlohmann::json body;
  try {
    body = rest::object_body(request, "fuzz");
  } catch (const scanplan::http::HttpError&) {
    return 0;
  }
  check([&] {
    const double v = rest::coordinate(body, "x");
    if (!std::isfinite(v) || std::abs(v) > rest::kMaxCoordinateM) __builtin_trap();
  });
  check([&] {
    const double v = rest::number_in(body, "alpha", 0, 1);
    if (!(v >= 0 && v <= 1)) __builtin_trap();
  });
  check([&] { (void)rest::decided_by(body); });
  check([&] { (void)rest::author_of(body); });
  check([&] {
    const std::string t =
        rest::text_in(body, "reason", rest::kMaxReasonBytes, scanplan::TextKind::kProse);
    if (t.size() > rest::kMaxReasonBytes) __builtin_trap();
  });
  return 0;
}

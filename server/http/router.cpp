#include "http/router.hpp"

#include <algorithm>
#include <iostream>
#include <optional>
#include <stdexcept>

#include "http/http_error.hpp"
#include "http/percent_encoding.hpp"

namespace scanplan::http {
namespace {

// Splits "/a/b%2Fc" into {"a", "b/c"}: decoding after splitting keeps %2F inside its segment.
// nullopt on a bad escape (the parser normally rejects those first).
std::optional<std::vector<std::string>> split_path(std::string_view path) {
  std::vector<std::string> segments;
  if (path.empty() || path.front() != '/') return std::nullopt;
  path.remove_prefix(1);
  while (true) {
    const std::size_t slash = path.find('/');
    auto decoded = percent_decode(path.substr(0, slash), false);
    if (!decoded) return std::nullopt;
    segments.push_back(std::move(*decoded));
    if (slash == std::string_view::npos) return segments;
    path.remove_prefix(slash + 1);
  }
}

std::string_view raw_path(const Request& request) {
  // The router works on the still-encoded target; fall back to path for hand-built requests.
  const std::string_view target = request.target.empty() ? request.path : request.target;
  return target.substr(0, target.find('?'));
}

}  // namespace

Router::Router(Log log) : log_(std::move(log)) {
  if (!log_) log_ = [](std::string_view message) { std::cerr << message << std::endl; };
}

void Router::add(std::string method, std::string pattern, Handler handler) {
  if (method.empty()) throw std::invalid_argument("route method must not be empty");
  if (!handler) throw std::invalid_argument("route " + pattern + " has no handler");
  if (pattern.empty() || pattern.front() != '/') {
    throw std::invalid_argument("route pattern '" + pattern + "' must start with '/'");
  }
  Route route{method, pattern, {}, std::move(handler)};
  std::string_view rest(pattern);
  rest.remove_prefix(1);
  while (true) {
    const std::size_t slash = rest.find('/');
    const std::string_view text = rest.substr(0, slash);
    Segment segment;
    const std::size_t open = text.find('{');
    if (open == std::string_view::npos) {
      if (text.find('}') != std::string_view::npos) {
        throw std::invalid_argument("route pattern '" + pattern + "' has an unmatched '}'");
      }
      segment.prefix = std::string(text);
    } else {
      const std::size_t close = text.find('}', open);
      if (close == std::string_view::npos || close == open + 1 ||
          text.find_first_of("{}", open + 1) != close ||
          text.find_first_of("{}", close + 1) != std::string_view::npos) {
        throw std::invalid_argument("route pattern '" + pattern +
                                    "' needs one non-empty {name} per segment");
      }
      segment.prefix = std::string(text.substr(0, open));
      segment.capture = std::string(text.substr(open + 1, close - open - 1));
      segment.suffix = std::string(text.substr(close + 1));
      segment.is_capture = true;
    }
    route.segments.push_back(std::move(segment));
    if (slash == std::string_view::npos) break;
    rest.remove_prefix(slash + 1);
  }
  for (const Route& existing : routes_) {
    if (existing.method == route.method && existing.pattern == route.pattern) {
      throw std::invalid_argument("route " + method + " " + pattern + " is registered twice");
    }
  }
  routes_.push_back(std::move(route));
}

void Router::set_fallback(Handler handler) {
  fallback_ = std::move(handler);
}

bool Router::match(const Route& route, const std::vector<std::string>& segments, Params* params) {
  if (route.segments.size() != segments.size()) return false;
  Params captured;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    const Segment& pattern = route.segments[i];
    const std::string& actual = segments[i];
    if (!pattern.is_capture) {
      if (actual != pattern.prefix) return false;
      continue;
    }
    const std::size_t affixes = pattern.prefix.size() + pattern.suffix.size();
    if (actual.size() <= affixes || !actual.starts_with(pattern.prefix) ||
        !actual.ends_with(pattern.suffix)) {
      return false;
    }
    captured[pattern.capture] = actual.substr(pattern.prefix.size(), actual.size() - affixes);
  }
  if (params) *params = std::move(captured);
  return true;
}

bool Router::more_specific(const Route& a, const Route& b) {
  // Rank per segment: literal > capture with affixes > bare capture; the first difference decides.
  const auto rank = [](const Segment& s) {
    if (!s.is_capture) return 2;
    return s.prefix.empty() && s.suffix.empty() ? 0 : 1;
  };
  for (std::size_t i = 0; i < a.segments.size() && i < b.segments.size(); ++i) {
    const int ra = rank(a.segments[i]);
    const int rb = rank(b.segments[i]);
    if (ra != rb) return ra > rb;
  }
  return false;
}

Response Router::route(const Request& request) const {
  const auto segments = split_path(raw_path(request));
  if (!segments) {
    return Response::error(400, "bad_request", "malformed percent-encoding in request path");
  }

  const Route* best = nullptr;
  const Route* best_get = nullptr;
  std::vector<std::string> allowed;
  for (const Route& route : routes_) {
    if (!match(route, *segments, nullptr)) continue;
    if (std::find(allowed.begin(), allowed.end(), route.method) == allowed.end()) {
      allowed.push_back(route.method);
    }
    if (route.method == request.method && (!best || more_specific(route, *best))) best = &route;
    if (route.method == "GET" && (!best_get || more_specific(route, *best_get))) best_get = &route;
  }
  if (!best && request.method == "HEAD") best = best_get;

  if (best) {
    Params params;
    match(*best, *segments, &params);
    return invoke(best->handler, request, params);
  }
  if (allowed.empty()) {
    if (fallback_) return invoke(fallback_, request, {});
    return Response::error(404, "not_found", "no resource at " + std::string(raw_path(request)));
  }

  if (best_get && std::find(allowed.begin(), allowed.end(), "HEAD") == allowed.end()) {
    allowed.push_back("HEAD");
  }
  std::string allow;
  for (const std::string& method : allowed) {
    if (!allow.empty()) allow += ", ";
    allow += method;
  }
  Response response =
      Response::error(405, "method_not_allowed",
                      "method " + request.method + " is not allowed here; allowed: " + allow);
  response.set_header("Allow", allow);
  return response;
}

Response Router::invoke(const Handler& handler, const Request& request,
                        const Params& params) const {
  const auto internal_error = [&](std::string_view what) {
    log_("http: " + request.method + " " + request.target + " failed: " + std::string(what));
    return Response::error(500, "internal",
                           "internal error while handling the request; see the server log");
  };
  try {
    return handler(request, params);
  } catch (const HttpError& e) {
    if (e.status() < 400 || e.status() > 599) return internal_error(e.what());
    return Response::error(e.status(), e.code(), e.what());
  } catch (const std::exception& e) {
    return internal_error(e.what());
  } catch (...) {
    return internal_error("unknown exception");
  }
}

}  // namespace scanplan::http

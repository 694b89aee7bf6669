#pragma once

#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "http/request.hpp"
#include "http/response.hpp"

namespace scanplan::http {

// Dispatches requests to handlers by method and path pattern.
//
// A pattern is a path whose segments are literals or contain one capture, "{name}", optionally
// with a literal prefix/suffix in the same segment: "/api/v1/scans/{id}",
// "/api/v1/layers/{layer}.png". Captures match one non-empty segment and are percent-decoded
// per segment, so an encoded "/" (%2F) stays inside the capture. When several patterns match,
// the one with literals in earlier segments wins, so "/scans/latest" beats "/scans/{id}".
//
// Unknown path: the fallback if set, else 404. Known path, other method: 405 with Allow.
// HEAD uses the GET handler when no HEAD route exists (the server drops the body).
// A handler throwing HttpError answers with that error; any other exception becomes a 500 whose
// details go to the log, not to the client.
class Router {
 public:
  using Params = std::map<std::string, std::string>;
  using Handler = std::function<Response(const Request&, const Params&)>;
  using Log = std::function<void(std::string_view)>;

  // log receives handler failures; empty means stderr.
  explicit Router(Log log = {});

  // Throws std::invalid_argument for a malformed pattern or a method/pattern registered twice.
  void add(std::string method, std::string pattern, Handler handler);
  void set_fallback(Handler handler);

  Response route(const Request& request) const;

 private:
  struct Segment {
    std::string prefix;  // the whole segment for literals
    std::string capture;
    std::string suffix;
    bool is_capture = false;
  };
  struct Route {
    std::string method;
    std::string pattern;
    std::vector<Segment> segments;
    Handler handler;
  };

  static bool match(const Route& route, const std::vector<std::string>& segments, Params* params);
  static bool more_specific(const Route& a, const Route& b);
  Response invoke(const Handler& handler, const Request& request, const Params& params) const;

  std::vector<Route> routes_;
  Handler fallback_;
  Log log_;
};

}  // namespace scanplan::http

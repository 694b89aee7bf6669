#include "rest/api.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "app/domain_json.hpp"
#include "common/iso_time.hpp"
#include "http/http_error.hpp"
#include "http/websocket_handshake.hpp"
#include "rest/request_parsing.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Request;
using http::Response;
using nlohmann::json;
using rest::query_number;
using rest::query_scan_id;

Api::Api(ApiParts parts, const Auth& auth, std::string session_dir)
    : app_(parts),
      auth_(auth),
      session_dir_(std::move(session_dir)),
      started_(std::chrono::system_clock::now()) {}

void Api::install(http::Router& router) {
  router.add("GET", "/api/v1/health", [this](const Request&, const auto&) { return health(); });
  router.add("GET", "/api/v1/session", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return session(r);
  });
  router.add("GET", "/api/v1/map.drc", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return map_drc(r);
  });
  router.add("GET", "/api/v1/layers/{layer}.png", [this](const Request& r, const auto& params) {
    require(r, Role::kViewer);
    return layer(params.at("layer"));
  });
  router.add("GET", "/api/v1/scans", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return list_scans();
  });
  router.add("GET", "/api/v1/scans/{id}", [this](const Request& r, const auto& params) {
    require(r, Role::kViewer);
    return get_scan(params.at("id"));
  });
  router.add("POST", "/api/v1/scans", [this](const Request& r, const auto&) {
    require(r, Role::kOperator);
    return post_scan(r);
  });
  router.add("DELETE", "/api/v1/scans/{id}", [this](const Request& r, const auto& params) {
    require(r, Role::kOperator);
    return set_scan_excluded(r, params.at("id"), true);
  });
  router.add("POST", "/api/v1/scans/{id}/restore", [this](const Request& r, const auto& params) {
    require(r, Role::kOperator);
    return set_scan_excluded(r, params.at("id"), false);
  });
  router.add("GET", "/api/v1/candidates", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return candidates(r);
  });
  for (const std::string action : {"approve", "reject", "cancel"}) {
    router.add("POST", "/api/v1/candidates/{id}/" + action,
               [this, action](const Request& r, const auto& params) {
                 require(r, Role::kOperator);
                 return decide(r, params.at("id"), action);
               });
  }
  for (const std::string action : {"finish", "resume"}) {
    router.add("POST", "/api/v1/mission/" + action, [this, action](const Request& r, const auto&) {
      require(r, Role::kOperator);
      return end_mission(r, action == "finish");
    });
  }
  router.add("GET", "/api/v1/report.html", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return report();
  });
  router.add("GET", "/api/v1/export/{file}", [this](const Request& r, const auto& params) {
    require(r, Role::kViewer);
    return export_file(params.at("file"));
  });
  router.add("POST", "/api/v1/goals", [this](const Request& r, const auto&) {
    require(r, Role::kOperator);
    return post_goal(r);
  });
  router.add("GET", "/api/v1/decisions", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return decisions(r);
  });
  router.add("GET", "/api/v1/params", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return get_params();
  });
  router.add("PUT", "/api/v1/params", [this](const Request& r, const auto&) {
    require(r, Role::kOperator);
    return put_params(r);
  });
  router.add("POST", "/api/v1/scan", [this](const Request& r, const auto&) {
    require(r, Role::kOperator);
    return request_scan(r);
  });
  router.add("GET", "/api/v1/annotations", [this](const Request& r, const auto&) {
    require(r, Role::kViewer);
    return list_annotations();
  });
  router.add("POST", "/api/v1/annotations", [this](const Request& r, const auto&) {
    require(r, Role::kOperator);
    return post_annotation(r);
  });
  router.add("DELETE", "/api/v1/annotations/{id}", [this](const Request& r, const auto& params) {
    require(r, Role::kOperator);
    return delete_annotation(r, params.at("id"));
  });
  router.add("GET", "/api/v1/events", [this](const Request& r, const auto&) { return events(r); });
}

std::optional<Response> Api::admit(const Request& head) const {
  const auto length = head.header("Content-Length");
  const bool body = head.header("Transfer-Encoding") || (length && *length != "0");
  if (!body) return std::nullopt;
  try {
    require(head, Role::kOperator);
  } catch (const HttpError& e) {
    return Response::error(e.status(), e.code(), e.what());
  }
  return std::nullopt;
}

void Api::require(const Request& request, Role needed) const {
  const Role role = auth_.role_of(request);
  if (role == Role::kNone) {
    throw HttpError(401, "unauthorized",
                    "a valid token is required: send 'Authorization: Bearer <token>'");
  }
  if (needed == Role::kOperator && role != Role::kOperator) {
    throw HttpError(403, "forbidden", "this action needs an operator token; yours is a viewer's");
  }
}

Response Api::health() const {
  return Response::json(200, {{"status", "ok"}, {"bridges", app_.dds.connected_bridges()}});
}

Response Api::session(const Request& request) const {
  const std::size_t scan_count = app_.map.scan_count();
  const std::optional<StoredScan> last = app_.map.last_scan();
  json robots = json::object();
  for (const auto& [id, r] : app_.robots.states()) robots[id] = robot_json(r);
  json j = {{"session_dir", session_dir_},
            {"started", iso8601_utc(started_)},
            {"scans", scan_count},
            {"points", app_.map.point_count()},
            {"bridges", app_.dds.connected_bridges()},
            {"robots", robots},
            {"role", auth_.role_of(request) == Role::kOperator ? "operator" : "viewer"}};
  j["areas"] = areas_json(app_.map.areas());
  j["mission"] = progress_json(progress());
  if (const auto g = app_.map.layer_geometry()) j["layers"] = layer_geometry_json(*g);
  // A reopened session is not an empty one: its scans are coming back.
  if (const auto r = app_.intake.rebuilding()) {
    j["rebuilding"] = {{"done", r->done}, {"total", r->total}};
  } else {
    j["rebuilding"] = nullptr;
  }
  j["scans_not_in_map"] = not_in_map_json(app_.intake.not_in_map());
  if (const auto f = app_.intake.last_storage_failure()) {
    j["storage_failure"] = {{"at", f->at}, {"message", f->message}};
  } else {
    j["storage_failure"] = nullptr;
  }
  if (last) {
    const Bounds3 b = app_.map.bounds();
    j["bounds"] = {{"min", {b.min.x(), b.min.y(), b.min.z()}},
                   {"max", {b.max.x(), b.max.y(), b.max.z()}}};
    j["last_scan"] = {{"id", last->id},
                      {"robot", last->robot},
                      {"points", last->points},
                      {"pose", pose_json(last->placed)}};
  }
  return Response::json(200, j);
}

Response Api::events(const Request& r) const {
  const auto q = r.query.find("token");
  const Role role = q != r.query.end() ? auth_.role_of_token(q->second) : auth_.role_of(r);
  if (role == Role::kNone) {
    return Response::error(401, "unauthorized",
                           "a valid token is required: ?token=T or Authorization: Bearer T");
  }
  // A browser names the page that opens the socket: only our own page may (another site could
  // otherwise use a token it got hold of from the operator's browser). Clients that are not
  // browsers send no Origin.
  if (const auto origin = r.header("Origin")) {
    const std::string_view host = r.header("Host").value_or("");
    if (*origin != "http://" + std::string(host) && *origin != "https://" + std::string(host)) {
      return Response::error(403, "forbidden_origin",
                             "the events socket is only open to this server's own page, not to " +
                                 std::string(origin->substr(0, 100)));
    }
  }
  return http::websocket_handshake_response(r, app_.hub.adopt(r.peer));
}

}  // namespace scanplan::server

#pragma once

#include <chrono>
#include <nlohmann/json.hpp>
#include <string>

#include "app/annotations.hpp"
#include "app/live_map.hpp"
#include "app/mission.hpp"
#include "app/mission_progress.hpp"
#include "app/plan_book.hpp"
#include "app/robot_board.hpp"
#include "app/scan_intake.hpp"
#include "dds/dds_link.hpp"
#include "http/router.hpp"
#include "http/websocket_hub.hpp"
#include "rest/auth.hpp"

namespace scanplan::server {

// What the handlers work on: the application's parts, owned by main.
namespace rest {
// `base` with the parameters of a PUT /api/v1/params body (α, the policy, the target region,
// the no-go zones, ...) changed; http::HttpError 400 naming the first bad one.
MissionParams params_from(const nlohmann::json& body, MissionParams base);
}  // namespace rest

struct ApiParts {
  LiveMap& map;
  PlanBook& plans;
  const RobotBoard& robots;
  ScanIntake& intake;
  DdsLink& dds;
  Mission& mission;
  Annotations& annotations;
  http::WebSocketHub& hub;
};

// The REST API (DESIGN.md "REST") and the events WebSocket: handlers translate HTTP to calls on
// the application and back, and are the only code that knows HTTP status codes. They hold no
// state of their own beyond the session's start time.
class Api {
 public:
  Api(ApiParts parts, const Auth& auth, std::string session_dir);
  void install(http::Router& router);
  // http::ServerConfig::admit: a request that brings a body (every body goes to an operator's
  // route) needs an operator token before a byte of it is read: 401 without a valid token, 403
  // with a viewer's. Requests without a body are left to their route's own check.
  std::optional<http::Response> admit(const http::Request& head) const;

 private:
  // Throws HttpError 401/403 unless the request carries a token with at least `needed`.
  void require(const http::Request& request, Role needed) const;

  http::Response health() const;
  http::Response session(const http::Request& request) const;
  http::Response map_drc(const http::Request& request) const;
  http::Response layer(const std::string& name) const;
  http::Response request_scan(const http::Request& request);
  http::Response post_scan(const http::Request& request);
  nlohmann::json live_scan_json(const StoredScan& s,
                                const std::map<std::int64_t, std::string>& waiting) const;
  http::Response list_scans() const;
  http::Response get_scan(const std::string& id) const;
  // DELETE /api/v1/scans/{id} (excluded) and POST /api/v1/scans/{id}/restore.
  http::Response set_scan_excluded(const http::Request& request, const std::string& id,
                                   bool excluded);
  http::Response candidates(const http::Request& request) const;
  http::Response get_params() const;
  http::Response put_params(const http::Request& request);
  http::Response post_goal(const http::Request& request);
  http::Response decisions(const http::Request& request) const;
  http::Response decide(const http::Request& request, const std::string& id,
                        const std::string& action);
  // GET /api/v1/export/{map.ply,map.las,poses.csv,annotations.geojson}.
  http::Response export_file(const std::string& name) const;
  // POST /api/v1/mission/finish and /resume: the operator ends the mission, or takes it up.
  http::Response end_mission(const http::Request& request, bool finish);
  // How far the mission has come (GET /api/v1/session's "mission").
  MissionProgress progress() const;
  // GET /api/v1/report.html: the mission report.
  http::Response report() const;
  http::Response list_annotations() const;
  http::Response post_annotation(const http::Request& request);
  http::Response delete_annotation(const http::Request& request, const std::string& id);
  // GET /api/v1/events: the WebSocket upgrade. Browsers cannot set headers on a WebSocket: the
  // token may come as ?token=.
  http::Response events(const http::Request& request) const;

  ApiParts app_;
  const Auth& auth_;
  std::string session_dir_;
  std::chrono::system_clock::time_point started_;
};

}  // namespace scanplan::server

#include "api.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <nlohmann/json.hpp>

#include "http/http_error.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Request;
using http::Response;
using nlohmann::json;

namespace {

json vec3(const Eigen::Vector3f& v) {
  return json::array({v.x(), v.y(), v.z()});
}

json pose_json(const Pose& p) {
  return {{"x", p.x}, {"y", p.y}, {"z", p.z}, {"yaw_deg", rad2deg(p.yaw)}};
}

json areas_json(const MapAreas& a) {
  return {{"completed_m2", a.completed_m2},
          {"low_resolution_m2", a.low_resolution_m2},
          {"unscanned_m2", a.unscanned_m2},
          {"movable_m2", a.movable_m2}};
}

json scan_json(const StoredScan& s, const std::optional<MapAreas>& areas) {
  return {{"id", s.id},
          {"robot", s.robot},
          {"points", s.points},
          {"estimated", pose_json(s.estimated)},
          {"placed", pose_json(s.placed)},
          {"received_at", s.received_at},
          {"areas", areas ? areas_json(*areas) : json(nullptr)}};
}

json candidate_json(const CandidateRecord& r, const std::string& robot, std::uint64_t plan) {
  const Candidate& c = r.candidate;
  json path = json::array();
  for (const auto& p : c.path) path.push_back({p.x(), p.y()});
  return {{"id", r.id},
          {"robot", robot},
          {"plan", plan},
          {"rank", r.rank},
          {"state", r.state},
          {"note", r.note},
          {"custom", r.custom},
          {"x", c.position.x()},
          {"y", c.position.y()},
          {"z", c.position.z()},
          {"f", c.f},
          {"gain_unscanned_m2", c.gain_unscanned_m2},
          {"gain_low_res_m2", c.gain_low_res_m2},
          {"travel_m", c.travel_m},
          {"score", c.score},
          {"path", path}};
}

json geometry_json(const LayerGeometry& g) {
  return {{"min", {g.min_x, g.min_y}},
          {"max", {g.max_x, g.max_y}},
          {"px_per_m", g.px_per_m},
          {"width", g.width},
          {"height", g.height}};
}

// A scan id from the query: a whole number >= 0.
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

// A required, finite number from the query string.
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

std::string iso_time(std::chrono::system_clock::time_point t) {
  const std::time_t tt = std::chrono::system_clock::to_time_t(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace

Api::Api(ScanStore& store, ScanIntake& intake, DdsLink& dds, Mission& mission,
         Annotations& annotations, const Auth& auth, std::string session_dir)
    : store_(store),
      intake_(intake),
      dds_(dds),
      mission_(mission),
      annotations_(annotations),
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
  return Response::json(200, {{"status", "ok"}, {"bridges", dds_.connected_bridges()}});
}

Response Api::session(const Request& request) const {
  const std::size_t scan_count = store_.scan_count();
  const std::optional<StoredScan> last = store_.last_scan();
  json robots = json::object();
  for (const auto& [id, r] : store_.robot_states()) {
    const bool connected = r.connection.connected;
    robots[id] = {{"connected", connected},
                  {"lost_at", connected ? json(nullptr) : json(r.connection.lost_at)},
                  {"lost_reason", connected ? json(nullptr) : json(r.connection.reason)},
                  {"state", r.status.state},
                  {"command_id", r.status.command_id},
                  {"message", r.status.message},
                  {"pose", pose_json(r.status.reported)},
                  {"scan",
                   {{"command_id", r.scan.command_id},
                    {"state", r.scan.state},
                    {"fraction", r.scan.fraction},
                    {"message", r.scan.message}}}};
  }
  json j = {{"session_dir", session_dir_},
            {"started", iso_time(started_)},
            {"scans", scan_count},
            {"points", store_.point_count()},
            {"bridges", dds_.connected_bridges()},
            {"robots", robots},
            {"role", auth_.role_of(request) == Role::kOperator ? "operator" : "viewer"}};
  j["areas"] = areas_json(store_.areas());
  if (const auto g = store_.layer_geometry()) j["layers"] = geometry_json(*g);
  if (last) {
    const Bounds3 b = store_.bounds();
    j["bounds"] = {{"min", vec3(b.min)}, {"max", vec3(b.max)}};
    j["last_scan"] = {{"id", last->id},
                      {"robot", last->robot},
                      {"points", last->points},
                      {"pose", pose_json(last->placed)}};
  }
  return Response::json(200, j);
}

Response Api::map_drc(const Request& request) const {
  ScanStore::EncodedMap encoded;
  const bool has_since = request.query.count("since") > 0;
  const bool has_until = request.query.count("until") > 0;
  if (has_until) {
    const std::int64_t since = has_since ? query_scan_id(request, "since") : 0;
    const std::int64_t until = query_scan_id(request, "until");
    if (until < since) {
      throw HttpError(400, "bad_request", "'until' must not be less than 'since'");
    }
    encoded = store_.encoded_range(since, until);
  } else if (has_since) {
    encoded = store_.encoded_since(query_scan_id(request, "since"));
  } else {
    encoded = store_.encoded_map();
  }
  Response r;
  if (encoded.draco) {
    r = Response::bytes(*encoded.draco, "application/octet-stream");
  } else {
    r.status = 204;
  }
  r.set_header("Cache-Control", "no-store");
  // The newest scan included, for the next ?since=.
  r.set_header("X-Scanplan-Last-Scan", std::to_string(encoded.last_scan));
  return r;
}

Response Api::layer(const std::string& name) const {
  const auto& names = ScanStore::layer_names();
  if (std::find(names.begin(), names.end(), name) == names.end()) {
    throw HttpError(404, "unknown_layer",
                    "no layer '" + name + "'; the layers are regions, elevation and movable");
  }
  const LayerImage image = store_.layer(name);
  if (!image.png) {
    Response empty;
    empty.status = 204;
    return empty;
  }
  const auto& png = *image.png;
  Response r = Response::bytes(std::string(png.begin(), png.end()), "image/png");
  r.set_header("Cache-Control", "no-store");
  // Where the image lies in the map: its left, bottom, right and top edges in metres.
  const LayerGeometry& g = image.geometry;
  r.set_header("X-Scanplan-Layer-Bounds", std::to_string(g.min_x) + "," + std::to_string(g.min_y) +
                                              "," + std::to_string(g.max_x) + "," +
                                              std::to_string(g.max_y));
  return r;
}

Response Api::post_scan(const Request& request) {
  Pose estimated;
  estimated.x = query_number(request, "x");
  estimated.y = query_number(request, "y");
  estimated.z = query_number(request, "z");
  estimated.yaw = deg2rad(query_number(request, "yaw_deg"));
  std::string robot = "robot1";
  if (const auto it = request.query.find("robot"); it != request.query.end()) robot = it->second;
  if (robot.empty() || robot.size() > 64 || robot.find('/') != std::string::npos) {
    throw HttpError(400, "bad_request", "'robot' must be 1 to 64 characters without '/'");
  }
  if (request.body.empty()) {
    throw HttpError(400, "bad_request", "the body must be the scan as a PLY or PCD file");
  }
  PointCloud cloud;
  try {
    cloud = read_point_cloud_bytes(request.body, "the uploaded scan");
  } catch (const ScanFileError& e) {
    throw HttpError(400, "bad_scan", e.what());
  }
  if (cloud.empty()) throw HttpError(400, "bad_scan", "the uploaded scan holds no valid points");
  const auto stamp = std::chrono::duration_cast<std::chrono::nanoseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
  try {
    const StoredScan s = intake_.submit(robot, estimated, stamp, std::move(cloud));
    return Response::json(201, scan_json(s, std::nullopt));
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the scan could not be stored: ") + e.what());
  }
}

Response Api::list_scans() const {
  json list = json::array();
  for (const StoredScan& s : store_.scans()) list.push_back(scan_json(s, store_.areas_after(s.id)));
  return Response::json(200, {{"scans", list}, {"pending", intake_.pending()}});
}

Response Api::get_scan(const std::string& id) const {
  std::int64_t n = 0;
  const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), n);
  if (ec != std::errc() || end != id.data() + id.size() || n <= 0) {
    throw HttpError(400, "bad_request", "a scan id is a positive whole number, got '" + id + "'");
  }
  for (const StoredScan& s : store_.scans()) {
    if (s.id == n) return Response::json(200, scan_json(s, store_.areas_after(s.id)));
  }
  throw HttpError(404, "not_found", "no scan " + id + " in this session");
}

Response Api::candidates(const Request& request) const {
  const auto header = [](const PlanRecord& p) -> json {
    return {{"id", p.id},
            {"based_on_scan", p.based_on_scan},
            {"robot", p.robot},
            {"policy", p.policy},
            {"alpha", p.alpha},
            {"plan_ms", p.plan_ms},
            {"candidates", p.candidates.size()}};
  };
  // One plan per robot; the newest (the robot whose scan came last) first.
  std::vector<PlanRecord> plans;
  const auto robot = request.query.find("robot");
  if (robot != request.query.end()) {
    if (auto p = store_.plan(robot->second)) plans.push_back(std::move(*p));
  } else {
    plans = store_.plans();
    if (const auto latest = store_.plan()) {
      std::stable_partition(plans.begin(), plans.end(),
                            [&](const PlanRecord& p) { return p.robot == latest->robot; });
    }
  }
  json list = json::array(), headers = json::array();
  for (const PlanRecord& p : plans) {
    headers.push_back(header(p));
    for (const CandidateRecord& r : p.candidates) list.push_back(candidate_json(r, p.robot, p.id));
  }
  return Response::json(200, {{"plan", plans.empty() ? json(nullptr) : header(plans.front())},
                              {"plans", headers},
                              {"candidates", list}});
}

namespace {

json params_json(const MissionParams& p) {
  json target = nullptr;
  if (p.target) {
    target = json::array();
    for (const auto& c : p.target->corners()) target.push_back({c.x(), c.y()});
  }
  return {{"alpha", p.planner.alpha},
          {"policy", std::string(policy_name(p.planner.policy))},
          {"max_candidates", p.planner.max_candidates},
          {"travel_cost_per_m", p.planner.travel_cost_per_m},
          {"travel_free_m", p.planner.travel_free_m},
          {"completed_radius_m", p.planner.regions.completed_radius_m},
          {"max_step_m", p.planner.movable.max_step_m},
          {"target", target}};
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

}  // namespace

Response Api::decide(const Request& request, const std::string& id, const std::string& action) {
  std::uint64_t n = 0;
  const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), n);
  if (ec != std::errc() || end != id.data() + id.size() || n == 0) {
    throw HttpError(400, "bad_request",
                    "a candidate id is a positive whole number, got '" + id + "'");
  }
  // Who decided: the operator may name themselves; the token's role is recorded regardless.
  std::string by = "operator", reason;
  if (!request.body.empty()) {
    json body;
    try {
      body = json::parse(request.body);
    } catch (const json::exception&) {
      throw HttpError(400, "bad_request",
                      "the body, when given, must be JSON like {\"by\": \"name\"}");
    }
    if (body.contains("by") && body["by"].is_string())
      by = "operator " + body["by"].get<std::string>();
    if (body.contains("reason") && body["reason"].is_string())
      reason = body["reason"].get<std::string>();
  }
  try {
    json out;
    if (action == "approve") out = mission_.approve(n, by);
    if (action == "reject") out = mission_.reject(n, by, reason);
    if (action == "cancel") out = mission_.cancel(n, by);
    return Response::json(200, out);
  } catch (const MissionError& e) {
    throw HttpError(e.status, e.code, e.what());
  }
}

namespace {

// Who decided: the operator may name themselves in the body's "by".
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

}  // namespace

Response Api::post_goal(const Request& request) {
  json body;
  try {
    body = json::parse(request.body);
  } catch (const json::parse_error&) {
    throw HttpError(400, "bad_request",
                    "the body must be JSON like {\"x\": 12.5, \"y\": -3, \"robot\": \"robot1\"}");
  }
  if (!body.is_object()) throw HttpError(400, "bad_request", "the body must be a JSON object");
  for (const auto& [key, value] : body.items()) {
    if (key != "x" && key != "y" && key != "robot" && key != "by") {
      throw HttpError(400, "bad_request", "unknown field '" + key + "'");
    }
  }
  const auto metres = [&body](const char* key) {
    if (!body.contains(key) || !body[key].is_number() || !std::isfinite(body[key].get<double>())) {
      throw HttpError(400, "bad_request",
                      std::string("'") + key + "' is required: a finite number of metres");
    }
    return body[key].get<double>();
  };
  const double x = metres("x");
  const double y = metres("y");
  std::string robot;
  if (body.contains("robot")) {
    if (!body["robot"].is_string()) throw HttpError(400, "bad_request", "'robot' is a string");
    robot = body["robot"].get<std::string>();
  }
  try {
    const Mission::Proposed p = mission_.propose(x, y, robot, decided_by(body));
    return Response::json(201, candidate_json(p.candidate, p.robot, p.plan));
  } catch (const MissionError& e) {
    throw HttpError(e.status, e.code, e.what());
  }
}

Response Api::decisions(const Request& request) const {
  std::size_t limit = 200;
  if (const auto it = request.query.find("limit"); it != request.query.end()) {
    std::size_t n = 0;
    const auto [end, ec] =
        std::from_chars(it->second.data(), it->second.data() + it->second.size(), n);
    if (ec != std::errc() || end != it->second.data() + it->second.size() || n < 1 || n > 1000) {
      throw HttpError(400, "bad_request", "'limit' is a whole number 1..1000");
    }
    limit = n;
  }
  try {
    return Response::json(200, {{"decisions", mission_.log(limit)}});
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed", std::string("the session cannot be read: ") + e.what());
  }
}

Response Api::get_params() const {
  return Response::json(200, params_json(store_.params()));
}

Response Api::put_params(const Request& request) {
  json body;
  try {
    body = json::parse(request.body);
  } catch (const json::exception&) {
    throw HttpError(400, "bad_request", "the body must be a JSON object of parameters");
  }
  if (!body.is_object()) throw HttpError(400, "bad_request", "the body must be a JSON object");
  MissionParams p = store_.params();
  for (const auto& [key, value] : body.items()) {
    if (key == "alpha") {
      p.planner.alpha = number_in(body, "alpha", 0, 1);
    } else if (key == "policy") {
      const auto policy = value.is_string() ? parse_policy(value.get<std::string>()) : std::nullopt;
      if (!policy) {
        throw HttpError(400, "bad_request",
                        "'policy' must be paper, exhaustive, travel, nearest-frontier or random");
      }
      p.planner.policy = *policy;
    } else if (key == "max_candidates") {
      p.planner.max_candidates = static_cast<int>(number_in(body, "max_candidates", 1, 50));
    } else if (key == "travel_cost_per_m") {
      p.planner.travel_cost_per_m = number_in(body, "travel_cost_per_m", 0, 1e6);
    } else if (key == "travel_free_m") {
      p.planner.travel_free_m = number_in(body, "travel_free_m", 0, 1e5);
    } else if (key == "completed_radius_m") {
      p.planner.regions.completed_radius_m = number_in(body, "completed_radius_m", 1, 200);
    } else if (key == "max_step_m") {
      p.planner.movable.max_step_m = number_in(body, "max_step_m", 0.01, 2);
    } else if (key == "target") {
      std::vector<Eigen::Vector2d> corners;
      if (value.is_array()) {
        for (const auto& c : value) {
          if (!c.is_array() || c.size() != 2 || !c[0].is_number() || !c[1].is_number()) {
            corners.clear();
            break;
          }
          corners.emplace_back(c[0].get<double>(), c[1].get<double>());
        }
      }
      try {
        p.target = TargetRegion::polygon(corners);
      } catch (const std::invalid_argument& e) {
        throw HttpError(
            400, "bad_request",
            std::string("'target' must be [[x, y], ...] with at least 3 corners: ") + e.what());
      }
    } else {
      throw HttpError(400, "bad_request", "unknown parameter '" + key + "'");
    }
  }
  store_.set_params(p);
  return Response::json(200, params_json(store_.params()));
}

namespace {

// Annotations are bounded to where a map could be: a coordinate beyond this is a unit mistake
// (millimetres, a GPS longitude in the wrong field), not a place.
constexpr double kMaxCoordinateM = 1e6;

const char* const kAnnotationShape =
    "an annotation is {\"kind\": \"victim|hazard|blocked|note\", \"x\": m, \"y\": m, "
    "\"z\": m, \"text\": \"...\"} with optional \"by\": \"your name\"";

// The request body as a JSON object; 400 naming what is wrong otherwise.
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

// Who acts, recorded as decisions are: the role, and the name the operator gave, if any.
std::string author_of(const json& body) {
  if (!body.contains("by")) return "operator";
  const json& by = body.at("by");
  if (!by.is_string() || by.get<std::string>().empty() || by.get<std::string>().size() > 64) {
    throw HttpError(400, "bad_request", "'by' must be a name of 1 to 64 bytes");
  }
  return "operator " + by.get<std::string>();
}

}  // namespace

Response Api::list_annotations() const {
  json list = json::array();
  for (const Annotation& a : annotations_.list()) list.push_back(annotation_json(a));
  return Response::json(200, {{"annotations", list}});
}

Response Api::post_annotation(const Request& request) {
  const json body = object_body(request, kAnnotationShape);
  for (const auto& [key, value] : body.items()) {
    if (key != "kind" && key != "x" && key != "y" && key != "z" && key != "text" && key != "by") {
      throw HttpError(400, "bad_request", "unknown field '" + key + "': " + kAnnotationShape);
    }
  }
  if (!body.contains("kind") || !body["kind"].is_string() ||
      std::find(kAnnotationKinds.begin(), kAnnotationKinds.end(),
                body["kind"].get<std::string>()) == kAnnotationKinds.end()) {
    throw HttpError(400, "bad_request",
                    "'kind' must be \"victim\", \"hazard\", \"blocked\" or \"note\", got " +
                        (body.contains("kind") ? body["kind"].dump() : std::string("nothing")));
  }
  const std::string kind = body["kind"].get<std::string>();
  const double x = coordinate(body, "x"), y = coordinate(body, "y"), z = coordinate(body, "z");
  std::string text;
  if (body.contains("text")) {
    if (!body["text"].is_string()) throw HttpError(400, "bad_request", "'text' must be a string");
    text = body["text"].get<std::string>();
  }
  if (text.size() > kMaxAnnotationTextBytes) {
    throw HttpError(400, "bad_request",
                    "'text' is too long: " + std::to_string(text.size()) + " bytes, at most " +
                        std::to_string(kMaxAnnotationTextBytes));
  }
  if (kind == "note" && text.empty()) {
    throw HttpError(400, "bad_request", "'text' is required for a note");
  }
  const std::string author = author_of(body);
  try {
    return Response::json(201, annotation_json(annotations_.add(kind, x, y, z, text, author)));
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the annotation could not be stored: ") + e.what());
  }
}

Response Api::delete_annotation(const Request& request, const std::string& id) {
  std::int64_t n = 0;
  const auto [end, ec] = std::from_chars(id.data(), id.data() + id.size(), n);
  if (ec != std::errc() || end != id.data() + id.size() || n <= 0) {
    throw HttpError(400, "bad_request",
                    "an annotation id is a positive whole number, got '" + id + "'");
  }
  std::string by = "operator";
  if (!request.body.empty()) {
    const json body = object_body(request, "the body, when given, is {\"by\": \"your name\"}");
    for (const auto& [key, value] : body.items()) {
      if (key != "by") throw HttpError(400, "bad_request", "unknown field '" + key + "'");
    }
    by = author_of(body);
  }
  try {
    if (!annotations_.remove(n, by)) {
      throw HttpError(404, "not_found", "no annotation " + id + " in this session");
    }
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed",
                    std::string("the deletion could not be stored: ") + e.what());
  }
  return Response::json(200, {{"id", n}, {"deleted", true}, {"by", by}});
}

Response Api::request_scan(const Request& request) {
  std::string robot;
  if (const auto it = request.query.find("robot"); it != request.query.end()) robot = it->second;
  try {
    const std::uint32_t id = dds_.request_scan(robot);
    return Response::json(202, {{"command_id", id}, {"robot", robot.empty() ? "*" : robot}});
  } catch (const NoScannerError& e) {
    throw HttpError(503, "no_scanner", e.what());
  }
}

}  // namespace scanplan::server

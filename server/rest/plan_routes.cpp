#include "rest/api.hpp"

#include <algorithm>
#include <charconv>
#include <nlohmann/json.hpp>

#include "app/domain_json.hpp"
#include "http/http_error.hpp"
#include "rest/request_parsing.hpp"

namespace scanplan::server {

using http::HttpError;
using http::Request;
using http::Response;
using nlohmann::json;

namespace rest {

HttpError http_error(const MissionError& e) {
  switch (e.errc) {
    case MissionErrc::kNotFound:
      return HttpError(404, e.code, e.what());
    case MissionErrc::kConflict:
    case MissionErrc::kNoMap:
      return HttpError(409, e.code, e.what());
    case MissionErrc::kNoRobot:
      return HttpError(503, e.code, e.what());
    case MissionErrc::kUnknownRobot:
    case MissionErrc::kGoalRefused:
      break;
  }
  return HttpError(400, e.code, e.what());
}

}  // namespace rest

Response Api::candidates(const Request& request) const {
  // One plan per robot; the newest (the robot whose scan came last) first.
  std::vector<PlanRecord> plans;
  const auto robot = request.query.find("robot");
  if (robot != request.query.end()) {
    if (auto p = app_.plans.plan(rest::robot_in(robot->second))) plans.push_back(std::move(*p));
  } else {
    plans = app_.plans.plans();
    if (const auto latest = app_.plans.plan()) {
      std::stable_partition(plans.begin(), plans.end(),
                            [&](const PlanRecord& p) { return p.robot == latest->robot; });
    }
  }
  json list = json::array(), headers = json::array();
  for (const PlanRecord& p : plans) {
    headers.push_back(plan_header_json(p));
    for (const CandidateRecord& r : p.candidates) list.push_back(candidate_json(r, p.robot, p.id));
  }
  return Response::json(200,
                        {{"plan", plans.empty() ? json(nullptr) : plan_header_json(plans.front())},
                         {"plans", headers},
                         {"candidates", list}});
}

Response Api::decide(const Request& request, const std::string& id, const std::string& action) {
  const std::uint64_t n = rest::path_id(id, "a candidate id");
  // Who decided: the operator may name themselves; the token's role is recorded regardless.
  json body = json::object();
  if (!request.body.empty()) {
    body = rest::object_body(request,
                             "the body, when given, is {\"by\": \"name\", \"reason\": \"...\"}");
  }
  const std::string by = rest::decided_by(body);
  const std::string reason = rest::text_in(body, "reason", rest::kMaxReasonBytes, TextKind::kProse);
  try {
    if (action == "approve") return Response::json(200, approval_json(app_.mission.approve(n, by)));
    if (action == "reject") {
      return Response::json(200, rejection_json(app_.mission.reject(n, by, reason)));
    }
    return Response::json(200, cancellation_json(app_.mission.cancel(n, by)));
  } catch (const MissionError& e) {
    throw rest::http_error(e);
  }
}

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
    if (!robot.empty()) rest::robot_in(robot);
  }
  try {
    const Proposal p = app_.mission.propose(x, y, robot, rest::decided_by(body));
    return Response::json(201, candidate_json(p.candidate, p.robot, p.plan));
  } catch (const MissionError& e) {
    throw rest::http_error(e);
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
    json list = json::array();
    for (const SessionEvent& e : app_.mission.log(limit)) list.push_back(decision_json(e));
    return Response::json(200, {{"decisions", list}});
  } catch (const SessionStoreError& e) {
    throw HttpError(503, "storage_failed", std::string("the session cannot be read: ") + e.what());
  }
}

namespace {

// More zones than an operator draws by hand; each is checked against every candidate cell.
constexpr std::size_t kMaxNoGoZones = 100;

// A polygon [[x, y], ...] of the request, `what` naming it in the error.
TargetRegion region_from(const json& value, const std::string& what) {
  std::vector<Eigen::Vector2d> corners;
  if (value.is_array()) {
    for (const auto& c : value) {
      if (!c.is_array() || c.size() != 2 || !c[0].is_number() || !c[1].is_number() ||
          std::abs(c[0].get<double>()) > rest::kMaxCoordinateM ||
          std::abs(c[1].get<double>()) > rest::kMaxCoordinateM) {
        throw HttpError(400, "bad_request",
                        what + " must be [[x, y], ...]: corners of finite metres within ±" +
                            std::to_string(static_cast<long>(rest::kMaxCoordinateM)) + ", got " +
                            c.dump().substr(0, 80));
      }
      corners.emplace_back(c[0].get<double>(), c[1].get<double>());
    }
  }
  try {
    return TargetRegion::polygon(corners);
  } catch (const std::invalid_argument& e) {
    throw HttpError(400, "bad_request",
                    what + " is not a region the planner can take: " + e.what());
  }
}

}  // namespace

Response Api::get_params() const {
  return Response::json(200, params_json(app_.map.params()));
}

namespace rest {

MissionParams params_from(const json& body, MissionParams p) {
  for (const auto& [key, value] : body.items()) {
    if (key == "alpha") {
      p.planner.alpha = rest::number_in(body, "alpha", 0, 1);
    } else if (key == "policy") {
      const auto policy = value.is_string() ? parse_policy(value.get<std::string>()) : std::nullopt;
      if (!policy) {
        throw HttpError(400, "bad_request",
                        "'policy' must be paper, exhaustive, travel, nearest-frontier or random");
      }
      p.planner.policy = *policy;
    } else if (key == "max_candidates") {
      p.planner.max_candidates = static_cast<int>(rest::number_in(body, "max_candidates", 1, 50));
    } else if (key == "travel_cost_per_m") {
      p.planner.travel_cost_per_m = rest::number_in(body, "travel_cost_per_m", 0, 1e6);
    } else if (key == "travel_free_m") {
      p.planner.travel_free_m = rest::number_in(body, "travel_free_m", 0, 1e5);
    } else if (key == "completed_radius_m") {
      p.planner.regions.completed_radius_m = rest::number_in(body, "completed_radius_m", 1, 200);
    } else if (key == "max_step_m") {
      p.planner.movable.max_step_m = rest::number_in(body, "max_step_m", 0.01, 2);
    } else if (key == "target") {
      p.target = region_from(value, "'target'");
    } else if (key == "no_go") {
      if (!value.is_array() || value.size() > kMaxNoGoZones) {
        throw HttpError(400, "bad_request",
                        "'no_go' must be a list of at most " + std::to_string(kMaxNoGoZones) +
                            " polygons [[[x, y], ...], ...] ([] for none)");
      }
      p.planner.no_go.clear();
      for (std::size_t i = 0; i < value.size(); ++i) {
        p.planner.no_go.push_back(region_from(value[i], "no-go zone " + std::to_string(i + 1)));
      }
    } else {
      throw HttpError(400, "bad_request", "unknown parameter '" + key + "'");
    }
  }
  return p;
}

}  // namespace rest

Response Api::put_params(const Request& request) {
  json body;
  try {
    body = json::parse(request.body);
  } catch (const json::exception&) {
    throw HttpError(400, "bad_request", "the body must be a JSON object of parameters");
  }
  if (!body.is_object()) throw HttpError(400, "bad_request", "the body must be a JSON object");
  std::string by = "operator";
  if (body.contains("by")) {
    by = rest::author_of(body);
    body.erase("by");
  }
  const MissionParams p = rest::params_from(body, app_.map.params());
  // Every value is checked above, so a failure here is the machine's (memory); set_params then
  // leaves the parameters as they were.
  return Response::json(200, params_json(app_.mission.set_params(p, by)));
}

Response Api::end_mission(const Request& request, bool finish) {
  const json body = rest::by_and_reason(request);
  const std::string by = rest::decided_by(body);
  if (finish) {
    app_.mission.finish(by, rest::text_in(body, "reason", rest::kMaxReasonBytes, TextKind::kProse));
  } else {
    app_.mission.resume(by);
  }
  return Response::json(200, progress_json(progress()));
}

MissionProgress Api::progress() const {
  std::vector<MapAreas> after;
  for (const StoredScan& s : app_.map.scans()) {
    if (const auto a = app_.map.areas_after(s.id)) after.push_back(*a);
  }
  return mission_progress(app_.map.areas(), after, app_.plans.plans(), app_.mission.finished());
}

}  // namespace scanplan::server

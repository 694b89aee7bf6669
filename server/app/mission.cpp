#include "app/mission.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

#include "app/domain_json.hpp"
#include "common/iso_time.hpp"

namespace scanplan::server {

using nlohmann::json;

Mission::Mission(LiveMap& map, PlanBook& plans, const RobotBoard& robots, RobotLink& link,
                 SessionStore& session, const Events& events)
    : map_(map), plans_(plans), robots_(robots), link_(link), session_(session), events_(events) {
  // What the log says of the mission before a restart: whether the operator finished it (the
  // last finish or resume) and the points each robot refused, kept until a scan after the
  // refusal changes the map near them (the scans reload after this, see PlanBook).
  try {
    for (const SessionEvent& e : session_.events(1000000)) {
      if (e.kind == "resume") finished_.reset();
      if (e.kind != "finish" && e.kind != "refused") continue;
      const json d = json::parse(e.json, nullptr, false);
      if (e.kind == "finish") {
        finished_ = {d.is_object() ? d.value("by", std::string("operator")) : "operator", e.at};
      } else if (d.is_object() && d.value("x", json()).is_number() &&
                 d.value("y", json()).is_number() && d.value("robot", json()).is_string() &&
                 d.value("after_scan", json(0)).is_number_integer()) {
        // Only a refusal with its place and scan: an older row, or a damaged one, is passed over.
        plans_.restore_refusal(
            d["robot"].get<std::string>(),
            {{d["x"].get<double>(), d["y"].get<double>()}, d.value("after_scan", std::int64_t{0})});
      }
    }
  } catch (const std::exception& e) {
    spdlog::error("could not read the mission's log back: {}", e.what());
  }
}

void Mission::finish(const std::string& by, const std::string& reason) {
  std::lock_guard lock(mutex_);
  json details = {{"by", by}};
  if (!reason.empty()) details["reason"] = reason;
  record("finish", details);
  finished_ = {by, iso8601_utc_now(TimePrecision::kMilliseconds)};
}

void Mission::resume(const std::string& by) {
  std::lock_guard lock(mutex_);
  record("resume", {{"by", by}});
  finished_.reset();
}

std::optional<std::pair<std::string, std::string>> Mission::finished() const {
  std::lock_guard lock(mutex_);
  return finished_;
}

void Mission::record(const std::string& kind, json details) {
  details["kind"] = kind;
  events_.publish("mission", details);
  try {
    session_.append_event(kind, details.dump());
  } catch (const std::exception& e) {
    spdlog::error("could not record '{}' in the session: {}", kind, e.what());
  }
}

void Mission::record_event(const std::string& type, const json& details) {
  publish_recorded(events_, session_, type, details);
}

PlanBook::Found Mission::find(std::uint64_t id) const {
  if (auto found = plans_.find(id)) return std::move(*found);
  throw MissionError(MissionErrc::kNotFound, "not_found",
                     "no candidate " + std::to_string(id) +
                         " in the current plan (plans are "
                         "replaced after every scan: GET /api/v1/candidates)");
}

void Mission::require_open(const PlanBook::Found& found, std::uint64_t id) {
  // An interrupted move (its bridge was lost) may be decided on again once the robot is back.
  if (!is_open(found.candidate.state)) {
    throw MissionError(
        MissionErrc::kConflict, "conflict",
        "candidate " + std::to_string(id) + " is " + std::string(to_string(found.candidate.state)));
  }
}

void Mission::require_apart(const CandidateRecord& c) const {
  // Two robots are never sent to the same spot: the planner keeps each robot's candidates
  // away from the others' goals, and a choice made by hand is held to the same distance.
  const double keep_apart_m = map_.claim_separation_m();
  for (const auto& [other, move] : moving_) {
    const auto goal = plans_.find(move.candidate);
    if (!goal) continue;  // its plan is gone: the robot has scanned since
    const Eigen::Vector3d& at = goal->candidate.candidate.position;
    const double d = (at - c.candidate.position).head<2>().norm();
    if (d < keep_apart_m) {
      char why[160];
      std::snprintf(why, sizeof why,
                    "robot '%s' is already going to (%.1f, %.1f), %.1f m from there", other.c_str(),
                    at.x(), at.y(), d);
      throw MissionError(MissionErrc::kConflict, "conflict",
                         std::string(why) + ": choose a point at least " +
                             std::to_string(static_cast<int>(keep_apart_m)) + " m away");
    }
  }
}

MissionParams Mission::set_params(const MissionParams& params, const std::string& by) {
  map_.set_params(params);
  const MissionParams now = map_.params();
  const json j = params_json(now);
  try {
    session_.record_params(j.dump(), by);
  } catch (const std::exception& e) {
    // In force until a restart, which would fall back to the last ones kept.
    spdlog::error("could not keep the parameters in the session: {}", e.what());
  }
  record("params", {{"by", by}, {"params", j}});
  return now;
}

Approval Mission::approve(std::uint64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  const PlanBook::Found found = find(id);
  require_open(found, id);
  const std::string& robot = found.robot;
  const CandidateRecord& c = found.candidate;
  if (moving_.count(robot)) {
    throw MissionError(MissionErrc::kConflict, "conflict",
                       "robot '" + robot + "' is still carrying out an approved move");
  }
  require_apart(c);
  Approval out{id,
               robot,
               0,
               c.candidate.position.x(),
               c.candidate.position.y(),
               approach_yaw_deg(c.candidate),
               by};
  try {
    out.command_id = link_.request_move(robot, out.x, out.y, out.yaw_deg);
  } catch (const NoScannerError& e) {
    throw MissionError(MissionErrc::kNoRobot, "no_robot", e.what());
  }
  moving_[robot] = {out.command_id, id};
  plans_.set_candidate_state(id, CandidateState::kMoving);
  Pose goal;
  goal.x = out.x;
  goal.y = out.y;
  goal.z = c.candidate.position.z();
  goal.yaw = deg2rad(out.yaw_deg);
  link_.publish_goal(robot, goal);
  record("approve", approval_json(out));
  return out;
}

Rejection Mission::reject(std::uint64_t id, const std::string& by, const std::string& reason) {
  std::lock_guard lock(mutex_);
  require_open(find(id), id);
  plans_.set_candidate_state(id, CandidateState::kRejected, reason);
  const Rejection out{id, by, reason};
  record("reject", rejection_json(out));
  return out;
}

Cancellation Mission::cancel(std::uint64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  const std::string robot = find(id).robot;
  const auto it = moving_.find(robot);
  if (it == moving_.end() || it->second.candidate != id) {
    throw MissionError(MissionErrc::kConflict, "conflict",
                       "candidate " + std::to_string(id) + " is not being driven to");
  }
  // A move to where the robot stands supersedes the old goal: the robot stops there.
  const std::optional<Pose> reported = robots_.reported_pose(robot);
  const Pose here = reported.value_or(Pose{});
  try {
    link_.request_move(robot, here.x, here.y, rad2deg(here.yaw));
  } catch (const NoScannerError& e) {
    throw MissionError(MissionErrc::kNoRobot, "no_robot", e.what());
  }
  moving_.erase(it);
  plans_.set_candidate_state(id, CandidateState::kCancelled);
  // The robot's goal is now where it stands; the old one must not linger on the latched topic.
  if (reported) link_.publish_goal(robot, here);
  const Cancellation out{id, robot, by};
  record("cancel", cancellation_json(out));
  return out;
}

Proposal Mission::propose(double x, double y, const std::string& robot, const std::string& by) {
  // Not under mutex_: add_goal may wait for a scan being brought into the map, and the DDS
  // thread's on_status must not wait that long.
  const auto plan = plans_.plan(robot);
  if (!plan) {
    if (plans_.empty()) {
      throw MissionError(MissionErrc::kNoMap, "no_map", "there is no map yet: take a first scan");
    }
    throw MissionError(MissionErrc::kUnknownRobot, "unknown_robot",
                       "robot '" + robot + "' has no plan: it has not sent a scan yet");
  }
  Proposal out{{}, plan->robot, plan->id};
  try {
    out.candidate = map_.add_goal(x, y, plan->robot);
  } catch (const GoalRefused& e) {
    throw MissionError(e.code == "no_map" ? MissionErrc::kNoMap : MissionErrc::kGoalRefused, e.code,
                       e.what());
  }
  record("goal", proposal_json(out, by));
  return out;
}

std::vector<SessionEvent> Mission::log(std::size_t limit) const {
  return session_.events(limit);
}

void Mission::on_status(const std::string& robot, const RobotStatus& status) {
  std::lock_guard lock(mutex_);
  const auto it = moving_.find(robot);
  if (it == moving_.end() || status.command_id != it->second.command_id) return;
  const std::uint64_t candidate = it->second.candidate;
  if (status.state == RobotActivity::kArrived) {
    moving_.erase(it);
    plans_.set_candidate_state(candidate, CandidateState::kReached);
    record("arrived", {{"candidate", candidate}, {"robot", robot}, {"message", status.message}});
    try {
      const std::uint32_t scan = link_.request_scan(robot);
      record("scan_requested", {{"robot", robot}, {"command_id", scan}, {"after", "arrival"}});
    } catch (const std::exception& e) {
      spdlog::error("robot '{}' arrived but the scan command failed: {}", robot, e.what());
    }
  } else if (status.state == RobotActivity::kRefused) {
    moving_.erase(it);
    plans_.set_candidate_state(candidate, CandidateState::kRefused, status.message);
    json details = {{"candidate", candidate}, {"robot", robot}, {"message", status.message}};
    // Where, and after which scan: a restart reads the refusal back (restore_refusals).
    if (const auto found = plans_.find(candidate)) {
      details["x"] = found->candidate.candidate.position.x();
      details["y"] = found->candidate.candidate.position.y();
      details["after_scan"] = plans_.latest_scan();
    }
    record("refused", details);
  }
}

void Mission::on_robot_lost(const RobotLoss& loss) {
  std::lock_guard lock(mutex_);
  record_event("robot_lost",
               {{"robot", loss.robot}, {"reason", loss.reason}, {"lost_at", loss.lost_at}});
  if (loss.scan) {
    record_event("scan_failed", {{"robot", loss.robot},
                                 {"command_id", loss.scan->command_id},
                                 {"fraction", loss.scan->fraction},
                                 {"parts_discarded", loss.scan->parts_discarded},
                                 {"reason", kScanLostReason}});
  }
  const auto it = moving_.find(loss.robot);
  if (it == moving_.end()) return;
  // Where the robot stopped is unknown until its bridge reports again; the operator decides
  // anew (the candidate may be approved again once the robot is back).
  const std::uint64_t candidate = it->second.candidate;
  const std::uint32_t command = it->second.command_id;
  moving_.erase(it);
  const std::string note = "the move was interrupted: " + loss.reason;
  plans_.set_candidate_state(candidate, CandidateState::kInterrupted, note);
  record("interrupted", {{"candidate", candidate},
                         {"robot", loss.robot},
                         {"command_id", command},
                         {"message", note}});
}

void Mission::on_robot_back(const std::string& robot) {
  std::lock_guard lock(mutex_);
  record_event("robot_back", {{"robot", robot}});
}

}  // namespace scanplan::server

#include "mission.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>

namespace scanplan::server {

using nlohmann::json;

Mission::Mission(ScanStore& store, DdsLink& dds, SessionStore& session, const Events& events)
    : store_(store), dds_(dds), session_(session), events_(events) {}

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
  events_.publish(type, details);
  try {
    session_.append_event(type, details.dump());
  } catch (const std::exception& e) {
    spdlog::error("could not record '{}' in the session: {}", type, e.what());
  }
}

CandidateRecord Mission::find(std::uint64_t id, std::string* robot) const {
  for (const PlanRecord& plan : store_.plans()) {
    for (const auto& c : plan.candidates) {
      if (c.id == id) {
        if (robot) *robot = plan.robot;
        return c;
      }
    }
  }
  throw MissionError(404, "not_found",
                     "no candidate " + std::to_string(id) +
                         " in the current plan (plans are "
                         "replaced after every scan: GET /api/v1/candidates)");
}

json Mission::approve(std::uint64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  std::string robot;
  const CandidateRecord c = find(id, &robot);
  // An interrupted move (its bridge was lost) may be approved again once the robot is back.
  if (c.state != "proposed" && c.state != "interrupted") {
    throw MissionError(409, "conflict", "candidate " + std::to_string(id) + " is " + c.state);
  }
  if (moving_.count(robot)) {
    throw MissionError(409, "conflict",
                       "robot '" + robot + "' is still carrying out an approved move");
  }
  // Two robots are never sent to the same spot: the planner keeps each robot's candidates
  // away from the others' goals, and a choice made by hand is held to the same distance.
  const double keep_apart_m = store_.claim_separation_m();
  for (const auto& [other, move] : moving_) {
    CandidateRecord goal;
    try {
      goal = find(move.candidate, nullptr);
    } catch (const MissionError&) {
      continue;  // its plan is gone: the robot has scanned since
    }
    const double d = (goal.candidate.position - c.candidate.position).head<2>().norm();
    if (d < keep_apart_m) {
      char why[160];
      std::snprintf(why, sizeof why,
                    "robot '%s' is already going to (%.1f, %.1f), %.1f m from there", other.c_str(),
                    goal.candidate.position.x(), goal.candidate.position.y(), d);
      throw MissionError(409, "conflict",
                         std::string(why) + ": choose a point at least " +
                             std::to_string(static_cast<int>(keep_apart_m)) + " m away");
    }
  }
  const double yaw_deg = approach_yaw_deg(c.candidate);
  std::uint32_t command = 0;
  try {
    command = dds_.request_move(robot, c.candidate.position.x(), c.candidate.position.y(), yaw_deg);
  } catch (const NoScannerError& e) {
    throw MissionError(503, "no_robot", e.what());
  }
  moving_[robot] = {command, id};
  store_.set_candidate_state(id, "moving");
  Pose goal;
  goal.x = c.candidate.position.x();
  goal.y = c.candidate.position.y();
  goal.z = c.candidate.position.z();
  goal.yaw = deg2rad(yaw_deg);
  dds_.publish_goal(robot, goal);
  const json out = {{"candidate", id},
                    {"robot", robot},
                    {"command_id", command},
                    {"x", c.candidate.position.x()},
                    {"y", c.candidate.position.y()},
                    {"yaw_deg", yaw_deg},
                    {"by", by}};
  record("approve", out);
  return out;
}

json Mission::reject(std::uint64_t id, const std::string& by, const std::string& reason) {
  std::lock_guard lock(mutex_);
  const CandidateRecord c = find(id, nullptr);
  if (c.state != "proposed" && c.state != "interrupted") {
    throw MissionError(409, "conflict", "candidate " + std::to_string(id) + " is " + c.state);
  }
  store_.set_candidate_state(id, "rejected", reason);
  const json out = {{"candidate", id}, {"by", by}, {"reason", reason}};
  record("reject", out);
  return out;
}

json Mission::cancel(std::uint64_t id, const std::string& by) {
  std::lock_guard lock(mutex_);
  std::string robot;
  const CandidateRecord c = find(id, &robot);
  const auto it = moving_.find(robot);
  if (it == moving_.end() || it->second.candidate != id) {
    throw MissionError(409, "conflict",
                       "candidate " + std::to_string(id) + " is not being driven to");
  }
  // A move to where the robot stands supersedes the old goal: the robot stops there.
  const auto states = store_.robot_states();
  const auto rs = states.find(robot);
  const Pose here = rs != states.end() ? rs->second.status.reported : Pose{};
  try {
    dds_.request_move(robot, here.x, here.y, rad2deg(here.yaw));
  } catch (const NoScannerError& e) {
    throw MissionError(503, "no_robot", e.what());
  }
  moving_.erase(it);
  store_.set_candidate_state(id, "cancelled");
  // The robot's goal is now where it stands; the old one must not linger on the latched topic.
  if (rs != states.end()) dds_.publish_goal(robot, here);
  const json out = {{"candidate", id}, {"robot", robot}, {"by", by}};
  record("cancel", out);
  return out;
}

Mission::Proposed Mission::propose(double x, double y, const std::string& robot,
                                   const std::string& by) {
  // Not under mutex_: add_goal may wait for a scan being brought into the map, and the DDS
  // thread's on_status must not wait that long.
  const auto plan = store_.plan(robot);
  if (!plan) {
    if (store_.plans().empty())
      throw MissionError(409, "no_map", "there is no map yet: take a first scan");
    throw MissionError(400, "unknown_robot",
                       "robot '" + robot + "' has no plan: it has not sent a scan yet");
  }
  CandidateRecord c;
  try {
    c = store_.add_goal(x, y, plan->robot);
  } catch (const GoalRefused& e) {
    throw MissionError(e.code == "no_map" ? 409 : 400, e.code, e.what());
  }
  record("goal", {{"candidate", c.id},
                  {"robot", plan->robot},
                  {"x", c.candidate.position.x()},
                  {"y", c.candidate.position.y()},
                  {"f", c.candidate.f},
                  {"travel_m", c.candidate.travel_m},
                  {"by", by}});
  return {c, plan->robot, plan->id};
}

json Mission::log(std::size_t limit) const {
  json out = json::array();
  for (const SessionEvent& e : session_.events(limit)) {
    json entry = json::parse(e.json, nullptr, false);
    if (!entry.is_object()) entry = json::object();
    entry["id"] = e.id;
    entry["at"] = e.at;
    entry["kind"] = e.kind;
    out.push_back(std::move(entry));
  }
  return out;
}

void Mission::on_status(const std::string& robot, const RobotStatus& status) {
  std::lock_guard lock(mutex_);
  const auto it = moving_.find(robot);
  if (it == moving_.end() || status.command_id != it->second.command_id) return;
  const std::uint64_t candidate = it->second.candidate;
  if (status.state == "arrived") {
    moving_.erase(it);
    store_.set_candidate_state(candidate, "reached");
    record("arrived", {{"candidate", candidate}, {"robot", robot}, {"message", status.message}});
    try {
      const std::uint32_t scan = dds_.request_scan(robot);
      record("scan_requested", {{"robot", robot}, {"command_id", scan}, {"after", "arrival"}});
    } catch (const std::exception& e) {
      spdlog::error("robot '{}' arrived but the scan command failed: {}", robot, e.what());
    }
  } else if (status.state == "refused") {
    moving_.erase(it);
    store_.set_candidate_state(candidate, "refused", status.message);
    record("refused", {{"candidate", candidate}, {"robot", robot}, {"message", status.message}});
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
                                 {"reason", DdsLink::kScanLostReason}});
  }
  const auto it = moving_.find(loss.robot);
  if (it == moving_.end()) return;
  // Where the robot stopped is unknown until its bridge reports again; the operator decides
  // anew (the candidate may be approved again once the robot is back).
  const std::uint64_t candidate = it->second.candidate;
  const std::uint32_t command = it->second.command_id;
  moving_.erase(it);
  const std::string note = "the move was interrupted: " + loss.reason;
  store_.set_candidate_state(candidate, "interrupted", note);
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

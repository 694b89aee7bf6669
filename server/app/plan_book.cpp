#include "app/plan_book.hpp"

#include <cmath>

#include "scanplan/geometry/pose.hpp"

namespace scanplan::server {
namespace {

// The candidate the plan's robot is driving to (an approved move under way), if any.
const CandidateRecord* active_goal(const PlanRecord& plan) {
  for (const CandidateRecord& c : plan.candidates) {
    if (c.state == CandidateState::kMoving) return &c;
  }
  return nullptr;
}

}  // namespace

double approach_yaw_deg(const Candidate& c) {
  const auto& path = c.path;
  if (path.size() < 2) return 0;
  const Eigen::Vector2d d = path.back() - path[path.size() - 2];
  return rad2deg(std::atan2(d.y(), d.x()));
}

std::optional<PlanRecord> PlanBook::plan(const std::string& robot) const {
  std::lock_guard lock(mutex_);
  const auto it = plans_.find(robot.empty() ? latest_robot_ : robot);
  if (it == plans_.end()) return std::nullopt;
  return it->second;
}

std::vector<PlanRecord> PlanBook::plans() const {
  std::lock_guard lock(mutex_);
  std::vector<PlanRecord> out;
  for (const auto& [robot, plan] : plans_) out.push_back(plan);
  return out;
}

bool PlanBook::empty() const {
  std::lock_guard lock(mutex_);
  return plans_.empty();
}

std::string PlanBook::latest_robot() const {
  std::lock_guard lock(mutex_);
  return latest_robot_;
}

void PlanBook::replace(const std::vector<PlanRecord>& plans, const std::string& latest_robot) {
  std::lock_guard lock(mutex_);
  for (const PlanRecord& record : plans) {
    if (const auto old = plans_.find(record.robot); old != plans_.end()) {
      for (auto& c : old->second.candidates) {
        if (c.state == CandidateState::kProposed) c.state = CandidateState::kSuperseded;
      }
    }
    plans_[record.robot] = record;
  }
  if (!latest_robot.empty()) latest_robot_ = latest_robot;
}

bool PlanBook::add_candidate(const std::string& robot, const CandidateRecord& candidate) {
  std::lock_guard lock(mutex_);
  const auto it = plans_.find(robot);
  if (it == plans_.end()) return false;
  it->second.candidates.push_back(candidate);
  return true;
}

bool PlanBook::set_candidate_state(std::uint64_t id, CandidateState state,
                                   const std::string& note) {
  std::lock_guard lock(mutex_);
  for (auto& [robot, plan] : plans_) {
    for (auto& c : plan.candidates) {
      if (c.id != id) continue;
      c.state = state;
      c.note = note;
      if (state == CandidateState::kRefused)
        refused_[robot].push_back({c.candidate.position.head<2>(), latest_scan_});
      if (state == CandidateState::kReached) {
        reached_[robot] = {c.candidate.position, c.candidate.travel_m};
      } else if (state != CandidateState::kRejected) {
        reached_.erase(robot);  // moving on, or stopped short of it
      }
      return true;
    }
  }
  return false;
}

std::vector<Eigen::Vector2d> PlanBook::refused_points(const std::string& robot) const {
  std::lock_guard lock(mutex_);
  std::vector<Eigen::Vector2d> points;
  if (const auto it = refused_.find(robot); it != refused_.end()) {
    for (const Refusal& r : it->second) points.push_back(r.at);
  }
  return points;
}

void PlanBook::forget_refusals_near(double x, double y, double radius_m, std::int64_t scan_id) {
  std::lock_guard lock(mutex_);
  latest_scan_ = std::max(latest_scan_, scan_id);
  const Eigen::Vector2d at(x, y);
  for (auto& [robot, refusals] : refused_) {
    std::erase_if(refusals, [&](const Refusal& r) {
      return r.after_scan < scan_id && (r.at - at).norm() <= radius_m;
    });
  }
}

void PlanBook::restore_refusal(const std::string& robot, const Refusal& refusal) {
  std::lock_guard lock(mutex_);
  refused_[robot].push_back(refusal);
}

std::int64_t PlanBook::latest_scan() const {
  std::lock_guard lock(mutex_);
  return latest_scan_;
}

std::optional<PlanBook::Found> PlanBook::find(std::uint64_t id) const {
  std::lock_guard lock(mutex_);
  for (const auto& [robot, plan] : plans_) {
    for (const auto& c : plan.candidates) {
      if (c.id == id) return Found{c, robot};
    }
  }
  return std::nullopt;
}

std::map<std::string, Eigen::Vector3d> PlanBook::driving_goals() const {
  std::lock_guard lock(mutex_);
  std::map<std::string, Eigen::Vector3d> goals;
  for (const auto& [robot, plan] : plans_) {
    if (const CandidateRecord* goal = active_goal(plan)) goals[robot] = goal->candidate.position;
  }
  return goals;
}

std::optional<ReachedGoal> PlanBook::take_reached_goal(const std::string& robot) {
  std::lock_guard lock(mutex_);
  const auto it = reached_.find(robot);
  if (it == reached_.end()) return std::nullopt;
  const ReachedGoal goal = it->second;
  reached_.erase(it);
  return goal;
}

std::vector<Eigen::Vector3d> PlanBook::claims_except(const std::string& robot) const {
  std::lock_guard lock(mutex_);
  std::vector<Eigen::Vector3d> claims;
  for (const auto& [id, plan] : plans_) {
    if (id == robot) continue;
    const CandidateRecord* goal = active_goal(plan);
    for (const CandidateRecord& c : plan.candidates) {
      if (!goal && c.state == CandidateState::kProposed && c.rank == 1) goal = &c;
    }
    if (goal) claims.push_back(goal->candidate.position);
  }
  return claims;
}

}  // namespace scanplan::server

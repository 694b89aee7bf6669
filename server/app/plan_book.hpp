#pragma once

#include <Eigen/Core>
#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "app/states.hpp"
#include "scanplan/planning/scan_planner.hpp"

namespace scanplan::server {

// One suggested scan point as the operator sees it.
struct CandidateRecord {
  std::uint64_t id = 0;  // unique in the session, across plans
  int rank = 0;          // 1 = best; 0 for the operator's own
  Candidate candidate;
  CandidateState state = CandidateState::kProposed;
  std::string note;     // why, for refused, rejected and interrupted
  bool custom = false;  // proposed by the operator (POST /api/v1/goals), not by the planner
};

struct PlanRecord {
  std::uint64_t id = 0;
  std::int64_t based_on_scan = 0;
  std::string robot;
  std::string policy;
  double alpha = 0;
  double plan_ms = 0;
  std::vector<CandidateRecord> candidates;
  double best_gain_m2 = 0;  // Plan::best_gain_m2
};

// Where a robot arrived that it was sent to: the candidate's place (map frame) and the length
// of the path the planner gave it there (Candidate::travel_m; odometry drifts with it).
struct ReachedGoal {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  double drive_m = 0;
};

// The heading a robot takes at candidate `c`: along the last leg of its path, so the scan starts
// looking where the robot went (0 without a path). Degrees, map frame.
double approach_yaw_deg(const Candidate& c);

// The plans the operator decides on: each robot's newest, with its candidates' states, and so
// where every robot is going. Thread-safe; never calls out while it holds its lock.
class PlanBook {
 public:
  // `robot`'s plan; empty: that of the robot whose scan came last. Nothing before its first plan.
  std::optional<PlanRecord> plan(const std::string& robot = "") const;
  // Every robot's plan, by robot id.
  std::vector<PlanRecord> plans() const;
  bool empty() const;
  // The robot whose scan came last (empty before any).
  std::string latest_robot() const;

  // Ids unique in the session.
  std::uint64_t new_plan_id() { return next_plan_id_++; }
  std::uint64_t new_candidate_id() { return next_candidate_id_++; }

  // The new plans replace their robots' old ones, whose undecided candidates are superseded.
  // `latest_robot` is the robot whose scan came last (empty: unchanged).
  void replace(const std::vector<PlanRecord>& plans, const std::string& latest_robot);
  // Adds a candidate (the operator's own goal) to `robot`'s plan; false without such a plan.
  bool add_candidate(const std::string& robot, const CandidateRecord& candidate);
  // Sets a candidate's state; false when the id is in no current plan.
  bool set_candidate_state(std::uint64_t id, CandidateState state, const std::string& note = "");
  // The candidate with this id and the robot whose plan holds it.
  struct Found {
    CandidateRecord candidate;
    std::string robot;
  };
  std::optional<Found> find(std::uint64_t id) const;

  // The goals robots are driving to (an approved move under way), by robot.
  std::map<std::string, Eigen::Vector3d> driving_goals() const;
  // Where `robot` arrived after an approved move (its candidate reached), once: the next scan
  // it sends was taken there (StoredScan::goal). A new approval, a refusal, a cancellation or an
  // interruption of that robot's move forgets it, so a scan after those is not claimed at a
  // place never reached.
  std::optional<ReachedGoal> take_reached_goal(const std::string& robot);
  // Where the robots other than `robot` are going to scan next: the goals of approved moves,
  // else the best candidates of their plans.
  std::vector<Eigen::Vector3d> claims_except(const std::string& robot) const;
  // The points `robot` refused to drive to (candidates set kRefused), which its plans leave out
  // until the map there changes: forget_refusals_near drops those within `radius_m` of scan
  // `scan_id` when it joined the map after the refusal. Each refusal remembers the newest scan
  // the map had then (after_scan), so a restarted server that reads the refusals back from the
  // session (restore_refusal) and then reloads the scans keeps exactly those still standing.
  struct Refusal {
    Eigen::Vector2d at;
    std::int64_t after_scan = 0;
  };
  std::vector<Eigen::Vector2d> refused_points(const std::string& robot) const;
  void forget_refusals_near(double x, double y, double radius_m, std::int64_t scan_id);
  void restore_refusal(const std::string& robot, const Refusal& refusal);
  // The newest scan that joined the map (forget_refusals_near): what a refusal now comes after.
  std::int64_t latest_scan() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, PlanRecord> plans_;              // by robot
  std::map<std::string, ReachedGoal> reached_;           // by robot: take_reached_goal
  std::map<std::string, std::vector<Refusal>> refused_;  // by robot
  std::int64_t latest_scan_ = 0;
  std::string latest_robot_;
  std::atomic<std::uint64_t> next_plan_id_{1}, next_candidate_id_{1};
};

}  // namespace scanplan::server

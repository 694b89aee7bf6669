#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "scanplan/planning/scan_planner.hpp"

namespace scanplan {

// One robot to plan for: where it stands (x, y, floor z).
struct FleetRobot {
  std::string id;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  std::optional<DriveDrift> drift;       // PlanInput::drift
  std::vector<Eigen::Vector2d> refused;  // PlanInput::refused
  // PlanInput::memo for this robot's plans against the claims as given; the turns after a robot
  // was decided claim more and plan without it.
  GainMemo* memo = nullptr;
};

struct FleetPlan {
  std::string robot;
  Plan plan;
};

// Next scan points for several robots on one map (paper §3.4 for each, coordinated): robots are
// decided one at a time, each with the scan points of those decided before (and `claimed`, the
// goals of robots already driving) claimed (PlanInput::claimed). At each turn every robot not
// yet decided is planned, and the robot whose best candidate scores highest is decided; when
// several score within PlannerConfig::fleet_tie_share of the highest, often the same spot seen
// from different robots, the one with the shortest drive to its own takes it, so robots do not
// cross the site to each other's side. No robot's candidate lies where another robot stands
// (PlanInput::occupied). With one robot this is plan_next_scan. `anchored` as
// PlanInput::anchored. Returns the plans in the order decided; a robot whose plan is empty is
// decided last.
std::vector<FleetPlan> plan_fleet(const MlsMap& map, const TargetRegion& target,
                                  const std::vector<Eigen::Vector2d>& scan_points,
                                  const std::vector<FleetRobot>& robots,
                                  std::vector<Eigen::Vector3d> claimed, const PlannerConfig& cfg,
                                  const MlsMap* anchored = nullptr);

}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <optional>
#include <string>

#include "scanplan/geometry/pose.hpp"

namespace scanplan {

// Where a scan joins the map, and how it got there.
struct Placement {
  Placement() = default;
  Placement(const Pose& reported_pose, const Pose& placed_pose, bool matched_by_match = false)
      : reported(reported_pose), placed(placed_pose), matched(matched_by_match) {}

  Pose reported;         // what the robot's pose sensors said (their frame)
  Pose placed;           // where the scan goes in the map frame
  bool matched = false;  // placed by a match the sanity check believed
  // The believed match's information over (x, y, z, yaw) in the map frame (MapMatch::
  // information); zero when the scan was not matched.
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  // Whose pose sensors reported it (the robot id): consecutive scans of one robot are related
  // by its odometry; scans of different robots are not.
  std::string track;
  // Where the robot was sent on the map before this scan (the approved candidate), if it was:
  // a scan that cannot be placed is claimed for the planner there as well as at its estimate,
  // which for a lost robot lies tens of metres off (MissionPipeline::unplaced_scan_points).
  std::optional<Eigen::Vector3d> goal;
  // How far the robot was sent along its path since its previous scan (Candidate::travel_m of
  // the approved goal), 0 when unknown. Odometry drifts with the path driven, and a drive round
  // a building can be four times the straight line between the two reports (DriftOdometry).
  double driven_m = 0;
};

}  // namespace scanplan

#pragma once

#include <optional>
#include <string>

#include "scanplan/geometry/pose.hpp"

namespace scanplan {

// Where a reported pose can be at all. A robot's pose is metres in the site's frame; a value
// beyond these is a unit mistake, a broken driver or a hostile client, and one such scan in the
// map spreads its bounds over the world and leaves the planner nothing (issue 16).
struct PoseLimits {
  // x and y: 100 km from the origin covers any site; float points keep 8 mm resolution there.
  double max_xy_m = 1e5;
  double max_z_m = 1e4;
  // Angles are taken modulo a turn, but beyond one turn a number is not an angle someone meant.
  double max_angle_deg = 360.0;
};

// Why `pose` cannot be a robot's pose (a message naming the field, its value and the limit), or
// nothing when it can.
std::optional<std::string> implausible_pose(const Pose& pose, const PoseLimits& limits = {});

}  // namespace scanplan

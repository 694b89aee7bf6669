#pragma once

#include "scanplan/geometry/pose.hpp"

namespace scanplan::testing_support {

// A pose on level ground: x, y (metres) and heading (degrees).
inline Pose ground_pose(double x, double y, double yaw_deg) {
  Pose p;
  p.x = x;
  p.y = y;
  p.yaw = deg2rad(yaw_deg);
  return p;
}

}  // namespace scanplan::testing_support

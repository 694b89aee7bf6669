#pragma once

#include "scanplan/geometry/pose.hpp"

namespace scanplan {

// Where one scan lies from another in the four parameters scan matching adjusts (paper §4.3:
// roll and pitch are measured): `to`'s position in `from`'s levelled frame (at `from`, turned by
// its yaw alone, z up) and the yaw between them. It does not depend on where `from` is nor on
// its yaw, only on its measured tilt, so a match's result, odometry and the pose graph's
// estimate all give the same kind of number.
struct RelativePose {
  double x = 0, y = 0, z = 0, yaw = 0;  // metres; radians, within (−π, π]
};

RelativePose relative_pose(const Pose& from, const Pose& to);
// `to` back from `from` and the relative pose; roll and pitch are `to_roll`, `to_pitch`.
Pose compose(const Pose& from, const RelativePose& relative, double to_roll, double to_pitch);
// The relative pose a 6-DOF transform mapping `to`'s scan frame into `from`'s gives, at
// `from`'s measured tilt.
RelativePose relative_pose(const Pose& from, const Eigen::Isometry3d& from_to);

}  // namespace scanplan

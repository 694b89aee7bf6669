#include "scanplan/graph/relative_pose.hpp"

#include <cmath>

namespace scanplan {

RelativePose relative_pose(const Pose& from, const Pose& to) {
  const double c = std::cos(from.yaw), s = std::sin(from.yaw);
  const double dx = to.x - from.x, dy = to.y - from.y;
  return {c * dx + s * dy, -s * dx + c * dy, to.z - from.z,
          std::remainder(to.yaw - from.yaw, 2 * M_PI)};
}

Pose compose(const Pose& from, const RelativePose& relative, double to_roll, double to_pitch) {
  const double c = std::cos(from.yaw), s = std::sin(from.yaw);
  Pose to;
  to.x = from.x + c * relative.x - s * relative.y;
  to.y = from.y + s * relative.x + c * relative.y;
  to.z = from.z + relative.z;
  to.yaw = std::remainder(from.yaw + relative.yaw, 2 * M_PI);
  to.roll = to_roll;
  to.pitch = to_pitch;
  return to;
}

RelativePose relative_pose(const Pose& from, const Eigen::Isometry3d& from_to) {
  return relative_pose(from, Pose::from_isometry(from.isometry() * from_to));
}

}  // namespace scanplan

#include "scanplan/geometry/pose.hpp"

#include <algorithm>
#include <cmath>

namespace scanplan {

Eigen::Quaterniond Pose::orientation() const {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                            Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
                            Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()));
}

Eigen::Isometry3d Pose::isometry() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = orientation().toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

Pose Pose::from_isometry(const Eigen::Isometry3d& T) {
  Pose p;
  p.x = T.translation().x();
  p.y = T.translation().y();
  p.z = T.translation().z();
  const Eigen::Matrix3d R = T.linear();
  // ZYX Euler angles; pitch is clamped so that numerical noise cannot push asin out of range.
  p.pitch = std::asin(std::clamp(-R(2, 0), -1.0, 1.0));
  p.roll = std::atan2(R(2, 1), R(2, 2));
  p.yaw = std::atan2(R(1, 0), R(0, 0));
  return p;
}

PoseChange pose_change(const Pose& from, const Pose& to) {
  return {std::hypot(to.x - from.x, to.y - from.y, to.z - from.z),
          std::abs(rad2deg(std::remainder(to.yaw - from.yaw, 2 * M_PI)))};
}

}  // namespace scanplan

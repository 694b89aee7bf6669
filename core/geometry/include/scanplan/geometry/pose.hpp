#pragma once

#include <Eigen/Geometry>

namespace scanplan {

// A robot pose on the ground. Roll and pitch come from the inclination sensor and are
// exact (paper §4.3), so matching adjusts only x, y, z and yaw.
struct Pose {
  double x = 0, y = 0, z = 0;
  double roll = 0, pitch = 0, yaw = 0;  // radians, applied as Rz(yaw)·Ry(pitch)·Rx(roll)

  Eigen::Isometry3d isometry() const;
  static Pose from_isometry(const Eigen::Isometry3d& T);
  Eigen::Quaterniond orientation() const;
  bool operator==(const Pose&) const = default;
};

// How far a pose moved: the distance in x, y and z (metres) and the turn in yaw, either way
// (degrees).
struct PoseChange {
  double metres = 0, degrees = 0;
};
PoseChange pose_change(const Pose& from, const Pose& to);

constexpr double deg2rad(double d) {
  return d * 0.017453292519943295;
}
constexpr double rad2deg(double r) {
  return r * 57.29577951308232;
}

}  // namespace scanplan

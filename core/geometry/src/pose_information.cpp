#include "scanplan/geometry/pose_information.hpp"

#include <Eigen/Geometry>

namespace scanplan {

Eigen::Matrix4d turned_information(const Eigen::Matrix4d& information, double turn) {
  // A vector v in the first frame reads R·v in the second, R = Rz(−turn); the quadratic form
  // vᵀ Ω v = (R v)ᵀ (R Ω Rᵀ) (R v).
  Eigen::Matrix4d R = Eigen::Matrix4d::Identity();
  R.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(-turn).toRotationMatrix();
  return R * information * R.transpose();
}

}  // namespace scanplan

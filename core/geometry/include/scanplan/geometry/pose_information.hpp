#pragma once

#include <Eigen/Core>

namespace scanplan {

// An information matrix over (x, y, z, yaw) whose x-y is expressed in one frame, expressed in a
// frame turned by `turn` radians about z from it (Ω' = R Ω Rᵀ, R turning x-y by −turn).
Eigen::Matrix4d turned_information(const Eigen::Matrix4d& information, double turn);

}  // namespace scanplan

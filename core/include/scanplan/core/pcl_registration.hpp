#pragma once

#include <Eigen/Geometry>

#include "scanplan/core/point_cloud.hpp"
#include "scanplan/core/registration_result.hpp"

namespace scanplan {

// PCL's matchers behind our interface, as baselines. PCL headers stay in the .cpp: they cost
// seconds of compile time in every file that includes them.
enum class PclMethod { kNdt, kIcp, kGicp };

// Defaults: the best of a few values each on the first 12 campus benchmark pairs (0.25 m voxels),
// so that the baselines are compared at their best, not at an arbitrary setting.
struct PclConfig {
  // pcl::NormalDistributionsTransform: one cell size (PCL has no narrowing schedule; of 1, 2, 3,
  // 4 and 6 m, 3 m matched most pairs) and the Moré-Thuente step bound.
  double ndt_resolution_m = 3.0;
  double ndt_step_size_m = 0.5;
  // pcl::IterativeClosestPoint: pairs farther apart than this are rejected (1, 2, 4 m tried).
  double icp_max_correspondence_m = 2.0;
  // pcl::GeneralizedIterativeClosestPoint: the same for GICP (1, 2, 4, 6, 10 m tried).
  double gicp_max_correspondence_m = 4.0;
  int max_iterations = 60;
  // PCL's stopping rules: the squared change of the transform between iterations, and the
  // relative change of the mean squared error.
  double transformation_epsilon = 1e-6;
  double euclidean_fitness_epsilon = 1e-6;
};

// Runs a PCL matcher from `initial`. PCL solves all 6 DOF; when `dof` is 4 the result keeps
// PCL's roll and pitch and says so in `message`, so a reader knows the constraint was not
// applied. Fills transform, iterations (as PCL counts them), converged and message.
RegistrationResult align_pcl(const PointCloud& target, const PointCloud& source,
                             const Eigen::Isometry3d& initial, PclMethod method, Dof dof,
                             const PclConfig& config);

}  // namespace scanplan

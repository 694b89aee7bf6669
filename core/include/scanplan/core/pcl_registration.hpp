#pragma once

#include <Eigen/Geometry>

#include "scanplan/core/point_cloud.hpp"
#include "scanplan/core/registration_result.hpp"

namespace scanplan {

// PCL's matchers behind our interface, as baselines. PCL headers stay in the .cpp: they cost
// seconds of compile time in every file that includes them.
enum class PclMethod { kNdt, kIcp, kGicp };

struct PclConfig {
  // pcl::NormalDistributionsTransform: one cell size (PCL has no narrowing schedule), Moré-Thuente
  // step bound, and PCL's stopping rule on the size of a step.
  double ndt_resolution_m = 2.0;
  double ndt_step_size_m = 0.5;
  // pcl::IterativeClosestPoint / GeneralizedIterativeClosestPoint: pairs farther apart than this
  // are rejected.
  double icp_max_correspondence_m = 2.0;
  int max_iterations = 60;
  double transformation_epsilon = 1e-8;  // squared change of the transform between iterations
  double euclidean_fitness_epsilon = 1e-8;
};

// Runs a PCL matcher from `initial`. PCL solves all 6 DOF; when `dof` is 4 the result keeps
// PCL's roll and pitch and says so in `message`, so a reader knows the constraint was not
// applied. Fills transform, iterations (as PCL counts them), converged and message.
RegistrationResult align_pcl(const PointCloud& target, const PointCloud& source,
                             const Eigen::Isometry3d& initial, PclMethod method, Dof dof,
                             const PclConfig& config);

}  // namespace scanplan

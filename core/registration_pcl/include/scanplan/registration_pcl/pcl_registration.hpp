#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string_view>
#include <variant>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/registration.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

// PCL's matchers behind our interface, as baselines for the CLI, the benchmarks and the tests;
// nothing in the server or the bridge links them. PCL headers stay in the .cpp: they cost
// seconds of compile time in every file that includes them.
enum class PclMethod {
  kNdt,   // pcl::NormalDistributionsTransform (6 DOF only)
  kIcp,   // pcl::IterativeClosestPoint (6 DOF only)
  kGicp,  // pcl::GeneralizedIterativeClosestPoint (6 DOF only)
};

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

// `config` with every length multiplied by `factor`. The transformation epsilon mixes rotation
// and translation and is left as it is.
PclConfig scale_lengths(const PclConfig& config, double factor);

// A PCL matcher through register_with: thinned, adapted to the scene, timed and scored exactly
// as our methods are.
RegistrationResult register_scans(const PointCloud& target, const PointCloud& source,
                                  const Eigen::Isometry3d& initial, PclMethod method,
                                  const RegistrationConfig& config = {}, const PclConfig& pcl = {});

// Our methods and PCL's under one name, for the tools that compare them.
using AnyMethod = std::variant<Method, PclMethod>;
// "ndt-icp", "ndt", "icp", "pcl-ndt", "pcl-icp", "pcl-gicp"; nullopt for anything else.
std::optional<AnyMethod> parse_any_method(std::string_view name);
std::string_view any_method_name(AnyMethod method);
RegistrationResult register_any(const PointCloud& target, const PointCloud& source,
                                const Eigen::Isometry3d& initial, AnyMethod method,
                                const RegistrationConfig& config = {}, const PclConfig& pcl = {});

}  // namespace scanplan

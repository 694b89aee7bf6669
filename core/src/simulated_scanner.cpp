#include "scanplan/core/simulated_scanner.hpp"

#include <cmath>

namespace scanplan {

PointCloud simulate_scan(const RayCaster& caster, const ScannerConfig& config,
                         const Pose& true_pose, std::uint64_t seed,
                         const ScanProgressFn& progress) {
  const int n_rot = config.rotation_samples();
  const int n_vert = config.vertical_samples();
  const Eigen::Isometry3d world_from_robot = true_pose.isometry();
  const Eigen::Matrix3d R = world_from_robot.linear();
  const Eigen::Vector3d sensor_robot(0, 0, config.mount_height_m);
  const Eigen::Vector3d sensor_world = world_from_robot * sensor_robot;

  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);

  // Elevations are shared by every stage angle; computing them once keeps the inner loop
  // to a few multiplies per beam.
  std::vector<double> cos_el(n_vert), sin_el(n_vert);
  const double el0 = -config.vertical_fov_deg / 2;
  for (int v = 0; v < n_vert; ++v) {
    const double el = deg2rad(el0 + v * config.vertical_step_deg);
    cos_el[v] = std::cos(el);
    sin_el[v] = std::sin(el);
  }

  PointCloud cloud;
  cloud.reserve(static_cast<std::size_t>(n_rot) * n_vert / 2);
  const int report_every = std::max(1, n_rot / 100);
  for (int r = 0; r < n_rot; ++r) {
    const double az = deg2rad(r * config.rotation_step_deg);
    const double ca = std::cos(az), sa = std::sin(az);
    for (int v = 0; v < n_vert; ++v) {
      const Eigen::Vector3d dir_robot(cos_el[v] * ca, cos_el[v] * sa, sin_el[v]);
      const Eigen::Vector3d dir_world = R * dir_robot;
      const auto hit =
          caster.cast(sensor_world, dir_world, config.min_range_m, config.max_range_m);
      if (!hit) continue;
      const double range = hit->range + config.range_noise_m * n01(rng);
      if (range < config.min_range_m || range > config.max_range_m) continue;
      cloud.push_back((sensor_robot + range * dir_robot).cast<float>(), hit->color);
    }
    if (progress && (r % report_every == report_every - 1 || r == n_rot - 1)) {
      if (!progress(static_cast<double>(r + 1) / n_rot)) break;
    }
  }
  return cloud;
}

Pose reported_pose(const Pose& truth, const PoseNoise& noise, std::mt19937_64& rng) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Pose p = truth;
  p.x += noise.xy_sigma_m * n01(rng);
  p.y += noise.xy_sigma_m * n01(rng);
  p.z += noise.z_sigma_m * n01(rng);
  p.yaw += deg2rad(noise.yaw_sigma_deg) * n01(rng);
  return p;
}

}  // namespace scanplan

#include "scanplan/sim/simulated_scanner.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#ifdef _OPENMP
#include <omp.h>
#endif

namespace scanplan {
namespace {

// SplitMix64's finaliser: neighbouring inputs give unrelated outputs, so the per-angle noise
// streams of one seed (and of consecutive seeds) do not overlap in any visible way.
std::uint64_t splitmix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// What one stage angle sees: one vertical fan.
struct Fan {
  const RayCaster& caster;
  const ScannerConfig& config;
  Eigen::Matrix3d world_from_robot;
  Eigen::Vector3d sensor_robot, sensor_world;
  std::vector<double> cos_el, sin_el;

  void scan(int stage_index, std::uint64_t seed, PointCloud& out) const {
    std::mt19937_64 rng(splitmix64(seed ^ splitmix64(static_cast<std::uint64_t>(stage_index))));
    std::normal_distribution<double> n01(0.0, 1.0);
    const double az = deg2rad(stage_index * config.rotation_step_deg);
    const double ca = std::cos(az), sa = std::sin(az);
    for (std::size_t v = 0; v < cos_el.size(); ++v) {
      const Eigen::Vector3d dir_robot(cos_el[v] * ca, cos_el[v] * sa, sin_el[v]);
      const Eigen::Vector3d dir_world = world_from_robot * dir_robot;
      const auto hit = caster.cast(sensor_world, dir_world, config.min_range_m, config.max_range_m);
      if (!hit) continue;
      const double range = hit->range + config.range_noise_m * n01(rng);
      if (range < config.min_range_m || range > config.max_range_m) continue;
      out.push_back((sensor_robot + range * dir_robot).cast<float>(), hit->color);
    }
  }
};

}  // namespace

PointCloud simulate_scan(const RayCaster& caster, const ScannerConfig& config,
                         const Pose& true_pose, std::uint64_t seed, const ScanProgressFn& progress,
                         int num_threads) {
  const int n_rot = config.rotation_samples();
  const int n_vert = config.vertical_samples();
  const Eigen::Isometry3d world_from_robot = true_pose.isometry();
  Fan fan{caster,
          config,
          world_from_robot.linear(),
          Eigen::Vector3d(0, 0, config.mount_height_m),
          Eigen::Vector3d::Zero(),
          std::vector<double>(n_vert),
          std::vector<double>(n_vert)};
  fan.sensor_world = world_from_robot * fan.sensor_robot;
  // Elevations are shared by every stage angle; computing them once keeps the inner loop
  // to a few multiplies per beam.
  const double el0 = -config.vertical_fov_deg / 2;
  for (int v = 0; v < n_vert; ++v) {
    const double el = deg2rad(el0 + v * config.vertical_step_deg);
    fan.cos_el[v] = std::cos(el);
    fan.sin_el[v] = std::sin(el);
  }

#ifdef _OPENMP
  const int threads = num_threads > 0 ? num_threads : omp_get_max_threads();
#else
  (void)num_threads;
#endif
  // With a progress callback the turn is done in slices of about 1 %, each spread over the
  // threads and reported (and possibly aborted) between slices, on this thread.
  const int report_every = std::max(1, n_rot / 100);
  const int slice = progress ? report_every : n_rot;
  std::vector<PointCloud> fans(static_cast<std::size_t>(std::min(slice, n_rot)));
  PointCloud cloud;
  cloud.reserve(static_cast<std::size_t>(n_rot) * n_vert / 2);
  for (int begin = 0; begin < n_rot; begin += slice) {
    const int end = std::min(n_rot, begin + slice);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int r = begin; r < end; ++r) {
      PointCloud& out = fans[static_cast<std::size_t>(r - begin)];
      out.points.clear();
      out.colors.clear();
      fan.scan(r, seed, out);
    }
    // Concatenating in stage order makes the result independent of which thread did what.
    for (int r = begin; r < end; ++r) cloud.append(fans[static_cast<std::size_t>(r - begin)]);
    if (progress && !progress(static_cast<double>(end) / n_rot)) break;
  }
  return cloud;
}

}  // namespace scanplan

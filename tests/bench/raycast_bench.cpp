// A full default scan of the campus world: the BVH caster on one and two threads against
// the brute-force caster (every primitive, every ground cell) in the same process. The
// simulate_scan figures include noise and point output; the speed-up compares casting alone,
// the same beams both ways. Prints one JSON line. Usage: raycast_bench [WORLD.json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "scanplan/sim/simulated_scanner.hpp"

namespace {

using Clock = std::chrono::steady_clock;

// The best of `repeats` runs: the machine is shared, and the minimum is the least disturbed.
double best_ms(int repeats, const std::function<void()>& run) {
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = Clock::now();
    run();
    best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  using namespace scanplan;
  const std::string world_file =
      argc > 1 ? argv[1] : SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json";
  const World world = load_world(world_file);
  const ScannerConfig& config = world.scanner;
  const Pose& pose = world.start;

  std::optional<RayCaster> caster;
  const double ms_build = best_ms(3, [&] { caster.emplace(world); });

  std::size_t points = 0;
  const double ms_1 =
      best_ms(3, [&] { points = simulate_scan(*caster, config, pose, 1, {}, 1).size(); });
  const double ms_2 = best_ms(3, [&] { simulate_scan(*caster, config, pose, 1, {}, 2); });

  // The scan's beams, in the world frame, for the cast-only comparisons.
  const int n_rot = config.rotation_samples(), n_vert = config.vertical_samples();
  const Eigen::Isometry3d T = pose.isometry();
  const Eigen::Vector3d sensor = T * Eigen::Vector3d(0, 0, config.mount_height_m);
  std::vector<Eigen::Vector3d> dirs;
  for (int r = 0; r < n_rot; ++r) {
    const double az = deg2rad(r * config.rotation_step_deg);
    for (int v = 0; v < n_vert; ++v) {
      const double el = deg2rad(-config.vertical_fov_deg / 2 + v * config.vertical_step_deg);
      dirs.push_back(T.linear() * Eigen::Vector3d(std::cos(el) * std::cos(az),
                                                  std::cos(el) * std::sin(az), std::sin(el)));
    }
  }
  const auto cast_all = [&](bool brute) {
    std::size_t hits = 0;
    for (const auto& d : dirs) {
      const auto h =
          brute ? caster->cast_brute_force(sensor, d, config.min_range_m, config.max_range_m)
                : caster->cast(sensor, d, config.min_range_m, config.max_range_m);
      hits += h.has_value();
    }
    return hits;
  };
  const double ms_cast = best_ms(3, [&] { cast_all(false); });
  const double ms_brute = best_ms(1, [&] { cast_all(true); });

  std::size_t mismatches = 0;
  for (const auto& d : dirs) {
    const auto a = caster->cast(sensor, d, config.min_range_m, config.max_range_m);
    const auto b = caster->cast_brute_force(sensor, d, config.min_range_m, config.max_range_m);
    if (a.has_value() != b.has_value() || (a && std::abs(a->range - b->range) > 1e-9)) ++mismatches;
  }

  const nlohmann::ordered_json out = {
      {"bench", "raycast_campus_scan"},
      {"world", world.name},
      {"pose", {pose.x, pose.y, pose.z, rad2deg(pose.yaw)}},
      {"rays", dirs.size()},
      {"points", points},
      {"primitives", caster->primitive_count()},
      {"ms_build", ms_build},
      {"ms_bvh_1thread", ms_1},
      {"ms_bvh_2threads", ms_2},
      {"ms_bvh_cast_only_1thread", ms_cast},
      {"ms_bruteforce_1thread", ms_brute},
      {"bruteforce", "every primitive and every ground cell for every ray (cast only)"},
      {"speedup", ms_brute / ms_cast},
      {"mismatches", mismatches},
  };
  std::printf("%s\n", out.dump().c_str());
  return mismatches == 0 ? 0 : 1;
}

// MLS map speed on the campus (issue 4): insert one ≥260k-point scan into a map that already
// holds five scans, and segment the regions and flood the movable region over the whole
// campus. The baseline, run on the same points in the same process, is the per-point update of
// elevation_mapping (Fankhauser et al., the widely used ROS peer): a range-dependent height
// variance, a Mahalanobis gate and a Kalman fusion into a fixed 2-D grid. Prints one JSON line.
// Usage: mls_bench [WORLD.json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace scanplan;

double best_ms(int repeats, const std::function<void()>& setup, const std::function<void()>& run) {
  double best = 1e300;
  for (int i = 0; i < repeats; ++i) {
    setup();
    const auto t0 = Clock::now();
    run();
    best = std::min(best, std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
  }
  return best;
}

// elevation_mapping's fusion of one measurement (ElevationMap::add): a point's height variance
// grows with its range; inside the Mahalanobis gate heights fuse by Kalman update, above it a
// higher point replaces the cell, below it is ignored.
class ElevationGrid {
 public:
  ElevationGrid(Eigen::Vector2d min, Eigen::Vector2d max, double cell)
      : min_(min),
        inv_(1.0 / cell),
        cols_(static_cast<int>(std::ceil((max.x() - min.x()) * inv_))),
        rows_(static_cast<int>(std::ceil((max.y() - min.y()) * inv_))),
        height_(static_cast<std::size_t>(cols_) * rows_, std::nanf("")),
        variance_(height_.size(), 0.0f) {}

  void add(const std::vector<Eigen::Vector3f>& points, const Eigen::Vector3f& sensor) {
    for (const auto& p : points) {
      const int i = static_cast<int>(std::floor((p.x() - min_.x()) * inv_));
      const int j = static_cast<int>(std::floor((p.y() - min_.y()) * inv_));
      if (i < 0 || j < 0 || i >= cols_ || j >= rows_) continue;
      const float range = (p - sensor).norm();
      const float sigma = 0.01f + 0.0008f * range * range;  // the laser sensor model's shape
      const float var = sigma * sigma;
      const std::size_t k = static_cast<std::size_t>(j) * cols_ + i;
      float& h = height_[k];
      float& v = variance_[k];
      if (std::isnan(h)) {
        h = p.z();
        v = var;
        continue;
      }
      const float mahalanobis = std::abs(p.z() - h) / std::sqrt(v);
      if (mahalanobis < 3.0f) {
        h = (v * p.z() + var * h) / (v + var);
        v = v * var / (v + var);
      } else if (p.z() > h) {
        h = p.z();
        v = var;
      }
    }
  }

 private:
  Eigen::Vector2d min_;
  double inv_;
  int cols_, rows_;
  std::vector<float> height_, variance_;
};

std::vector<Eigen::Vector3f> placed(const PointCloud& scan, const Pose& pose) {
  const Eigen::Isometry3f T = pose.isometry().cast<float>();
  std::vector<Eigen::Vector3f> out;
  out.reserve(scan.size());
  for (const auto& p : scan.points) out.push_back(T * p);
  return out;
}

// The scans of the benchmark: five already in the map, across the campus, and the measured one
// with a finer stage step, so that it holds at least 260k points.
struct Scans {
  std::vector<Eigen::Vector2d> earlier = {{80, 45}, {40, 60}, {120, 10}, {150, 90}, {60, 20}};
  std::vector<std::pair<PointCloud, Pose>> history;
  PointCloud scan;
  Pose at;
};

Scans simulate_scans(const World& world, const RayCaster& caster) {
  Scans s;
  for (const auto& xy : s.earlier) {
    Pose p = world.start;
    p.x = xy.x();
    p.y = xy.y();
    p.z = world.ground_height(p.x, p.y);
    s.history.emplace_back(simulate_scan(caster, world.scanner, p, s.history.size() + 1), p);
  }
  ScannerConfig dense = world.scanner;
  dense.rotation_step_deg = 0.27;
  s.at = world.start;
  s.at.x = 100;
  s.at.y = 70;
  s.at.z = world.ground_height(s.at.x, s.at.y);
  s.scan = simulate_scan(caster, dense, s.at, 99);
  return s;
}

// The baseline in the same run: elevation_mapping's per-point fusion of the same scans.
double elevation_mapping_ms(const World& world, const Scans& s, const Eigen::Vector3d& sensor) {
  std::optional<ElevationGrid> grid;
  const std::vector<Eigen::Vector3f> scan_map = placed(s.scan, s.at);
  const Eigen::Vector3f sensor_map = (s.at.isometry() * sensor).cast<float>();
  return best_ms(
      5,
      [&] {
        grid.emplace(world.bounds_min, world.bounds_max, 1.0);
        for (const auto& [c, p] : s.history)
          grid->add(placed(c, p), (p.isometry() * sensor).cast<float>());
      },
      [&] { grid->add(scan_map, sensor_map); });
}

}  // namespace

int main(int argc, char** argv) {
  const std::string world_file =
      argc > 1 ? argv[1] : SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json";
  const World world = load_world(world_file);
  const RayCaster caster(world);
  const Eigen::Vector3d sensor(0, 0, world.scanner.mount_height_m);
  const Scans s = simulate_scans(world, caster);
  const PointCloud& scan = s.scan;
  const Pose& at = s.at;

  MlsMap map;
  const auto build_history = [&] {
    map = MlsMap();
    for (const auto& [c, p] : s.history) map.insert_scan(c, p.isometry(), sensor);
  };
  const double ms_mls =
      best_ms(5, build_history, [&] { map.insert_scan(scan, at.isometry(), sensor); });
  MlsConfig no_fill_config;
  no_fill_config.fill_between_beams = false;
  MlsMap no_fill(no_fill_config);
  const std::vector<Eigen::Vector3f> scan_map = placed(scan, at);
  const double ms_mls_no_fill = best_ms(
      5, [&] { no_fill = MlsMap(no_fill_config); }, [&] { no_fill.insert(scan_map); });
  const double ms_elevation = elevation_mapping_ms(world, s, sensor);

  build_history();
  map.insert_scan(scan, at.isometry(), sensor);
  std::vector<Eigen::Vector2d> scan_points = s.earlier;
  scan_points.push_back({at.x, at.y});
  const TargetRegion target = world.target_region();
  RegionMap regions;
  MovableRegion movable;
  const double ms_segment = best_ms(
      5, [] {}, [&] { regions = segment_regions(map, target, scan_points); });
  const double ms_movable = best_ms(
      5, [] {},
      [&] {
        movable = movable_region(map, {at.x, at.y, at.z});
      });

  const double n = static_cast<double>(scan.size());
  const nlohmann::json out = {{"bench", "mls_campus"},
                              {"scan_points", scan.size()},
                              {"map_scans_before", s.history.size()},
                              {"ms_mls_insert_scan", ms_mls},
                              {"mpts_per_s_mls", n / ms_mls / 1000.0},
                              {"ms_mls_insert_no_fill", ms_mls_no_fill},
                              {"ms_elevation_mapping_update", ms_elevation},
                              {"mpts_per_s_elevation_mapping", n / ms_elevation / 1000.0},
                              {"reported_elevation_mapping_mpts_per_s", 1.5},
                              {"ms_segment_regions", ms_segment},
                              {"ms_movable_region", ms_movable},
                              {"occupied_cells", map.occupied_cells()},
                              {"completed_m2", regions.completed_m2()},
                              {"low_resolution_m2", regions.low_resolution_m2()},
                              {"unscanned_m2", regions.unscanned_m2()},
                              {"movable_m2", movable.area_m2()}};
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

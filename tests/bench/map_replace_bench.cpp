// How long the map takes to follow the pose graph late in a long session (issue 19: latency per
// scan not growing with the session): N campus scans are in the map when the graph moves six
// neighbouring ones by 5 cm and 0.1°. Measured: the map made anew only where the six lay and
// lie (MappingPipeline::replace_scans: the two halves of those tiles on two threads, and the
// same on one); the baseline in the same run is what the mission did before, every scan carried
// back into its own frame and inserted into an empty map, the regions and the movable region
// segmented after each. Checks that both give the same map, cell for cell. Prints one JSON line.
// Usage: map_replace_bench [SCANS=150] [WORLD.json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "scanplan/mapping/mapping_pipeline.hpp"
#include "scanplan/sim/simulated_scanner.hpp"
#include "scanplan/sim/world_traversability.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace scanplan;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

struct Scan {
  PointCloud in_map;
  Pose at;
  Bounds3 bounds;
};

// Scans at reachable places across the campus, at least 8 m apart, in a random order.
std::vector<Scan> simulate_session(const World& world, std::size_t n) {
  const RayCaster caster(world);
  const WorldTraversability ground(world, caster);
  const auto reach = ground.reach_from(world.start.x, world.start.y,
                                       world.ground_height(world.start.x, world.start.y));
  std::vector<std::size_t> cells;
  for (std::size_t c = 0; c < reach.z.size(); ++c) {
    if (reach.reachable(c)) cells.push_back(c);
  }
  std::mt19937_64 rng(19);
  std::shuffle(cells.begin(), cells.end(), rng);
  std::vector<Scan> out;
  for (const std::size_t c : cells) {
    if (out.size() == n) break;
    const Eigen::Vector2d xy = ground.cell_center(c);
    const bool crowded = std::any_of(out.begin(), out.end(), [&](const Scan& s) {
      return std::hypot(s.at.x - xy.x(), s.at.y - xy.y()) < 8.0;
    });
    if (crowded) continue;
    Scan s;
    s.at = ground.standing_pose(xy.x(), xy.y(), reach.z[c],
                                std::uniform_real_distribution<>(-M_PI, M_PI)(rng));
    const PointCloud own = simulate_scan(caster, world.scanner, s.at, out.size() + 1);
    const Eigen::Isometry3f T = s.at.isometry().cast<float>();
    s.in_map.reserve(own.size());
    for (std::size_t i = 0; i < own.size(); ++i)
      s.in_map.push_back(T * own.points[i], own.colors[i]);
    s.bounds = bounds_of(s.in_map);
    out.push_back(std::move(s));
  }
  return out;
}

std::vector<MappingPipeline::PlacedScan> placed(const std::vector<Scan>& scans) {
  std::vector<MappingPipeline::PlacedScan> out;
  for (const Scan& s : scans) out.push_back({&s.in_map, s.at, s.at, s.bounds});
  return out;
}

std::size_t cells_differing(const MlsMap& a, const MlsMap& b) {
  std::size_t n = 0;
  const auto same = [](const MlsCell& x, const MlsCell* y) {
    if (!y || x.size != y->size || x.interpolated != y->interpolated) return false;
    for (int k = 0; k < x.size; ++k) {
      const SurfacePatch& p = x.patches[k];
      const SurfacePatch& q = y->patches[k];
      if (p.min_z != q.min_z || p.max_z != q.max_z || p.mean_z != q.mean_z || p.m2 != q.m2 ||
          p.count != q.count || p.seen_from != q.seen_from) {
        return false;
      }
    }
    return true;
  };
  a.for_each_cell([&](CellIndex c, const MlsCell& x) { n += same(x, b.cell(c)) ? 0 : 1; });
  b.for_each_cell([&](CellIndex c, const MlsCell&) { n += a.cell(c) ? 0 : 1; });
  return n;
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t n = argc > 1 ? std::stoul(argv[1]) : 150;
  const std::string world_file =
      argc > 2 ? argv[2] : SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json";
  const World world = load_world(world_file);
  std::vector<Scan> scans = simulate_session(world, n);
  PipelineConfig config;
  config.sensor_height_m = world.scanner.mount_height_m;
  const Eigen::Vector3d sensor(0, 0, config.sensor_height_m);

  // The six scans nearest the middle one move by 5 cm and 0.1°, as the graph moves a chain.
  const Scan& middle = scans[scans.size() / 2];
  std::vector<std::size_t> order(scans.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::hypot(scans[a].at.x - middle.at.x, scans[a].at.y - middle.at.y) <
           std::hypot(scans[b].at.x - middle.at.x, scans[b].at.y - middle.at.y);
  });
  std::vector<Scan> after = scans;
  std::vector<Bounds3> changed;
  for (std::size_t k = 0; k < std::min<std::size_t>(6, order.size()); ++k) {
    Scan& s = after[order[k]];
    changed.push_back(s.bounds);
    Pose to = s.at;
    to.x += 0.04, to.y += 0.03, to.yaw += 0.1 * M_PI / 180;
    const Eigen::Isometry3f shift = (to.isometry() * s.at.isometry().inverse()).cast<float>();
    for (Eigen::Vector3f& p : s.in_map.points) p = shift * p;
    s.at = to;
    s.bounds = bounds_of(s.in_map);
    changed.push_back(s.bounds);
  }

  PipelineConfig one_thread = config;
  one_thread.threads = 1;
  const auto built = [&](const std::vector<Scan>& from, const PipelineConfig& with = {}) {
    PipelineConfig c = with;
    c.sensor_height_m = config.sensor_height_m;
    auto m = std::make_unique<MappingPipeline>(c);
    for (const Scan& s : from) m->add_placed_scan(s.in_map, s.at, s.at);
    return m;
  };
  constexpr int kRepeats = 3;
  Bounds3 everywhere;
  for (const Scan& s : after) {
    everywhere.extend(s.bounds.min);
    everywhere.extend(s.bounds.max);
  }
  double best_incremental = 1e300, best_baseline = 1e300, best_whole = 1e300, best_one = 1e300;
  std::unique_ptr<MappingPipeline> incremental, baseline;
  for (int r = 0; r < kRepeats; ++r) {
    incremental = built(scans);
    const auto t0 = Clock::now();
    incremental->replace_scans(placed(after), changed);
    best_incremental = std::min(best_incremental, ms_since(t0));

    // The same on one thread: what filling the two halves at once saves.
    std::unique_ptr<MappingPipeline> one = built(scans, one_thread);
    const auto t3 = Clock::now();
    one->replace_scans(placed(after), changed);
    best_one = std::min(best_one, ms_since(t3));

    // Every tile made anew, the regions once: what restricting to the changed tiles saves.
    std::unique_ptr<MappingPipeline> whole = built(scans);
    const auto t2 = Clock::now();
    whole->replace_scans(placed(after), {everywhere});
    best_whole = std::min(best_whole, ms_since(t2));

    const auto t1 = Clock::now();
    baseline = std::make_unique<MappingPipeline>(config);
    for (const Scan& s : after) {
      const Eigen::Isometry3f own_from_map = s.at.isometry().inverse().cast<float>();
      PointCloud own;
      own.reserve(s.in_map.size());
      for (std::size_t i = 0; i < s.in_map.size(); ++i) {
        own.push_back(own_from_map * s.in_map.points[i], s.in_map.colors[i]);
      }
      baseline->add_placed_scan(own, Pose{}, s.at);
    }
    best_baseline = std::min(best_baseline, ms_since(t1));
  }
  // From scratch with the moved scans where they now lie: what both must equal.
  const std::unique_ptr<MappingPipeline> scratch = built(after);
  MlsMap::Tiles tiles = scratch->map().tiles();
  for (const Bounds3& b : changed) tiles.add(b);
  std::size_t reinserted = 0, points = 0;
  for (const Scan& s : after) {
    reinserted += tiles.reaches(s.bounds) ? 1 : 0;
    points += s.in_map.size();
  }
  std::size_t tiles_total = 0, tiles_changed = 0;
  const auto extent = scratch->map().extent();
  for (int ty = extent->first.y >> MlsMap::kTileBits; ty <= extent->second.y >> MlsMap::kTileBits;
       ++ty) {
    for (int tx = extent->first.x >> MlsMap::kTileBits; tx <= extent->second.x >> MlsMap::kTileBits;
         ++tx) {
      ++tiles_total;
      tiles_changed += tiles.contains(tx, ty) ? 1 : 0;
    }
  }
  const nlohmann::json out = {
      {"bench", "map_replace"},
      {"scans", scans.size()},
      {"points", points},
      {"moved_scans", changed.size() / 2},
      {"tiles_changed", tiles_changed},
      {"tiles_in_extent", tiles_total},
      {"scans_reinserted", reinserted},
      {"ms_replace_changed_tiles", best_incremental},
      {"ms_replace_changed_tiles_one_thread", best_one},
      {"ms_baseline_rebuild_scan_by_scan", best_baseline},
      {"ms_every_tile_regions_once", best_whole},
      {"speedup", best_baseline / best_incremental},
      {"cells_differing_from_scratch", cells_differing(incremental->map(), scratch->map())},
      {"cells_differing_baseline", cells_differing(baseline->map(), scratch->map())},
      {"completed_m2_equal",
       incremental->regions()->completed_m2() == scratch->regions()->completed_m2()},
      {"occupied_cells", scratch->map().occupied_cells()}};
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

#include "scanplan/planning/visibility.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "mapping/mapping_test_support.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

using test::slab;

// A column of points from z0 to z1 in each cell of [x0, x1) × [y0, y1).
std::vector<Eigen::Vector3f> column(int x0, int x1, int y0, int y1, float z0, float z1) {
  std::vector<Eigen::Vector3f> pts;
  for (int x = x0; x < x1; ++x) {
    for (int y = y0; y < y1; ++y) {
      for (float z = z0; z <= z1 + 1e-4f; z += 0.25f)
        pts.emplace_back(static_cast<float>(x) + 0.5f, static_cast<float>(y) + 0.5f, z);
    }
  }
  return pts;
}

CellGrid<Region> raster(int cols, int rows) {
  return CellGrid<Region>({0, 0}, cols, rows, 1.0, Region::kUnscanned);
}

bool seen(const CellGrid<std::uint8_t>& g, int x, int y) {
  return g.values[*g.offset({x, y})] != 0;
}

TEST(Visibility, WallHidesTheGroundBehindIt) {
  MlsMap map;
  map.insert(slab(0, 60, 0, 40, 0.0f));
  map.insert(column(30, 31, 0, 20, 0.0f, 3.0f));  // a 3 m wall along x = 30, y 0..20
  const auto g = predict_visible(map, raster(60, 40), {20.5, 10.5}, 0.0, {});
  EXPECT_TRUE(seen(g, 20, 10)) << "the sensor's own cell";
  EXPECT_TRUE(seen(g, 25, 10));
  EXPECT_TRUE(seen(g, 20, 30));
  EXPECT_TRUE(seen(g, 30, 10)) << "the wall itself";
  for (const auto& [x, y] :
       std::vector<std::pair<int, int>>{{32, 10}, {35, 5}, {40, 12}, {45, 8}}) {
    EXPECT_FALSE(seen(g, x, y)) << x << ", " << y << " is behind the wall";
  }
  EXPECT_TRUE(seen(g, 38, 32)) << "past the wall's end";
}

TEST(Visibility, ThinObjectsCastNarrowShadows) {
  MlsMap map;
  map.insert(slab(0, 60, 0, 40, 0.0f));
  map.insert(column(20, 21, 20, 21, 0.0f, 5.0f));  // a post, alone in its cell, 10 m away
  const auto hidden_at_30m = [&](const VisibilityConfig& cfg) {
    const auto g = predict_visible(map, raster(60, 40), {10.5, 20.5}, 0.0, cfg);
    int hidden = 0;
    for (int y = 10; y < 31; ++y) hidden += !seen(g, 40, y);
    return hidden;
  };
  VisibilityConfig blocky;
  blocky.thin_object_radius_m = 0;
  const int thin = hidden_at_30m({}), full = hidden_at_30m(blocky);
  EXPECT_GE(thin, 1) << "straight behind the post";
  EXPECT_LT(thin, full) << "a 0.6 m post hides less than one filling its 1 m cell";
  EXPECT_LE(full, 6);
}

// Paper §3.1, Fig. 2-3: the MLS map keeps the ground under a canopy and the canopy over it.
// Here the sensor stands under a wide roof 3 to 3.5 m up; 25 m away a 5 m wall hides the foot
// of a 15 m building, whose face can only be seen by beams rising over the wall, which the
// roof stops.
TEST(Visibility, CanopyBlocksTheSkyButNotTheGroundBeneath) {
  MlsMap with_roof, without_roof;
  for (MlsMap* m : {&with_roof, &without_roof}) {
    m->insert(slab(0, 80, 0, 20, 0.0f));
    m->insert(column(45, 46, 0, 20, 0.0f, 5.0f));   // the wall
    m->insert(column(50, 53, 0, 20, 0.0f, 15.0f));  // the building
  }
  for (float z : {3.0f, 3.2f, 3.5f}) with_roof.insert(slab(5, 36, 0, 20, z));
  ASSERT_EQ(with_roof.cell({20, 10})->size, 2) << "ground and canopy are two surfaces";

  const auto open = predict_visible(without_roof, raster(80, 20), {20.5, 10.5}, 0.0, {});
  EXPECT_TRUE(seen(open, 50, 10)) << "the building's face, over the wall";
  EXPECT_FALSE(seen(open, 48, 10)) << "the ground between wall and building";
  const auto under = predict_visible(with_roof, raster(80, 20), {20.5, 10.5}, 0.0, {});
  EXPECT_TRUE(seen(under, 30, 15)) << "the canopy, seen from below";
  EXPECT_TRUE(seen(under, 25, 12)) << "the ground under the canopy";
  EXPECT_TRUE(seen(under, 40, 10)) << "the ground beyond the canopy, seen under its edge";
  EXPECT_TRUE(seen(under, 45, 10)) << "the wall";
  EXPECT_FALSE(seen(under, 50, 10)) << "the canopy stops the beams that would rise over the wall";
}

// Rings of a flat-ground scan from 1 m up with 0.5° beams: returns at 28.6 m, 38.2 m and
// 57.3 m; the filling closes the gaps up to 10 m (the 38.2 m ring) but not the 19 m one after.
TEST(Visibility, UnknownCellsAreGroundUpToWhereTheFillingStops) {
  MlsMap map;
  map.insert(slab(50, 71, 50, 71, 0.0f));  // known ground around the sensor only
  const auto g = predict_visible(map, raster(121, 121), {60.5, 60.5}, 0.0, {});
  const auto share = [&](const CellGrid<std::uint8_t>& grid, double r0, double r1) {
    int in = 0, on = 0;
    for (int y = 0; y < 121; ++y) {
      for (int x = 0; x < 121; ++x) {
        const double r = std::hypot(x + 0.5 - 60.5, y + 0.5 - 60.5);
        if (r < r0 || r >= r1) continue;
        ++in;
        on += seen(grid, x, y);
      }
    }
    return static_cast<double>(on) / in;
  };
  EXPECT_GT(share(g, 15, 37), 0.97);
  EXPECT_LT(share(g, 42, 54), 0.05) << "between the rings nothing is filled";
  EXPECT_GT(share(g, 56.5, 58.5), 0.3) << "the 57 m ring";

  VisibilityConfig empty;
  empty.unknown_as_ground = false;
  EXPECT_EQ(share(predict_visible(map, raster(121, 121), {60.5, 60.5}, 0.0, empty), 15, 60), 0.0);
}

TEST(Visibility, SplittingRaysNearTheSensorLosesAlmostNothing) {
  MlsMap map;
  map.insert(slab(0, 100, 0, 100, 0.0f));
  map.insert(column(40, 41, 20, 60, 0.0f, 4.0f));
  map.insert(column(55, 70, 62, 63, 0.0f, 2.0f));
  VisibilityConfig every_ray;
  every_ray.max_ray_spacing_m = 0.01;  // one ray per azimuth step all the way out
  const auto fine = predict_visible(map, raster(100, 100), {50.5, 50.5}, 0.0, every_ray);
  const auto tree = predict_visible(map, raster(100, 100), {50.5, 50.5}, 0.0, {});
  std::size_t both = 0, either = 0;
  for (std::size_t o = 0; o < fine.values.size(); ++o) {
    both += fine.values[o] && tree.values[o];
    either += fine.values[o] || tree.values[o];
  }
  EXPECT_GT(static_cast<double>(both) / static_cast<double>(either), 0.97);
}

// The prediction against what a simulated scan then really puts into the map (the scanner's
// 0.5° steps, range noise, the MLS gap filling), on the campus after two scans. Newly seen
// cells agree less: the prediction assumes open ground where buildings were never seen.
TEST(Visibility, AgreesWithTheScanItPredictsOnTheCampus) {
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  const RayCaster caster(w);
  const Eigen::Vector3d sensor(0, 0, w.scanner.mount_height_m);
  MlsMap map;
  std::vector<Eigen::Vector2d> scan_points = {{80, 45}, {60, 48}};
  for (std::size_t k = 0; k < scan_points.size(); ++k) {
    Pose p = w.start;
    p.x = scan_points[k].x();
    p.y = scan_points[k].y();
    map.insert_scan(simulate_scan(caster, w.scanner, p, k + 1), p.isometry(), sensor);
  }
  const RegionMap regions = segment_regions(map, w.target_region(), scan_points);
  Pose b = w.start;
  b.x = 100.5;
  b.y = 45.5;
  const CellIndex bc = map.index_of(b.x, b.y);
  ASSERT_NE(map.cell(bc), nullptr);
  const auto predicted =
      predict_visible(map, regions.cells, {b.x, b.y}, map.cell(bc)->patches[0].mean_z,
                      VisibilityConfig::from_scanner(w.scanner));
  MlsMap alone;
  alone.insert_scan(simulate_scan(caster, w.scanner, b, 7), b.isometry(), sensor);
  std::size_t both = 0, either = 0, both_new = 0, either_new = 0;
  for (std::size_t o = 0; o < predicted.values.size(); ++o) {
    const Region r = regions.cells.values[o];
    if (r == Region::kOutside) continue;
    const bool p = predicted.values[o] != 0;
    const bool a = alone.cell(regions.cells.index_at(o)) != nullptr;
    both += p && a;
    either += p || a;
    both_new += p && a && r == Region::kUnscanned;
    either_new += (p || a) && r == Region::kUnscanned;
  }
  const double iou = static_cast<double>(both) / static_cast<double>(either);
  const double iou_new = static_cast<double>(both_new) / static_cast<double>(either_new);
  RecordProperty("iou_all", std::to_string(iou));
  RecordProperty("iou_new", std::to_string(iou_new));
  EXPECT_GT(iou, 0.75);
  EXPECT_GT(iou_new, 0.6);
}

TEST(Visibility, BadInputIsRefusedWithAReason) {
  MlsMap map;
  map.insert(slab(0, 10, 0, 10, 0.0f));
  EXPECT_THROW(predict_visible(map, raster(10, 10), {500.0, 5.0}, 0.0, {}), std::out_of_range);
  EXPECT_THROW(predict_visible(map, raster(10, 10), {5.0, 5.0}, std::nan(""), {}),
               std::invalid_argument);
  VisibilityConfig bad;
  bad.azimuth_step_deg = 0;
  EXPECT_THROW(predict_visible(map, raster(10, 10), {5.0, 5.0}, 0.0, bad), std::invalid_argument);
  bad = {};
  bad.min_range_m = 100;
  EXPECT_THROW(predict_visible(map, raster(10, 10), {5.0, 5.0}, 0.0, bad), std::invalid_argument);
}

}  // namespace
}  // namespace scanplan

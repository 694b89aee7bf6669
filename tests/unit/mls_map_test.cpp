#include <gtest/gtest.h>

#include <random>

#include "scanplan/core/mls_map.hpp"
#include "scanplan/core/movable_region.hpp"
#include "scanplan/core/region_segmentation.hpp"
#include "scanplan/core/simulated_scanner.hpp"
#include "scanplan/core/top_view.hpp"

namespace scanplan {
namespace {

// A square of points filling cells [x0, x1) × [y0, y1) at height z, `per_cell` per 1 m cell.
std::vector<Eigen::Vector3f> slab(int x0, int x1, int y0, int y1, float z, int per_cell = 4) {
  std::vector<Eigen::Vector3f> pts;
  for (int x = x0; x < x1; ++x) {
    for (int y = y0; y < y1; ++y) {
      for (int k = 0; k < per_cell; ++k) {
        pts.emplace_back(x + 0.2f + 0.15f * k, y + 0.3f + 0.1f * k, z);
      }
    }
  }
  return pts;
}

TEST(MlsMap, PatchesSplitAtGapsTallerThanTheRobot) {
  MlsMap map;  // robot 1.5 m
  map.insert(std::vector<Eigen::Vector3f>{{0.5f, 0.5f, 0.0f},
                                          {0.5f, 0.5f, 0.02f},  // ground
                                          {0.5f, 0.5f, 3.0f},
                                          {0.5f, 0.5f, 3.4f},  // canopy
                                          {1.5f, 0.5f, 0.0f},
                                          {1.5f, 0.5f, 1.0f},  // a 1 m box
                                          {1.5f, 0.5f, 0.5f}});
  const MlsCell* tree = map.cell({0, 0});
  ASSERT_NE(tree, nullptr);
  ASSERT_EQ(tree->size, 2);
  EXPECT_FLOAT_EQ(tree->patches[0].max_z, 0.02f);
  EXPECT_NEAR(tree->patches[0].mean_z, 0.01f, 1e-6);
  EXPECT_FLOAT_EQ(tree->patches[1].min_z, 3.0f);
  EXPECT_FLOAT_EQ(tree->dem_height(), 3.4f);
  const MlsCell* box = map.cell({1, 0});
  ASSERT_EQ(box->size, 1) << "1 m of gap is no room for the robot: one deep patch";
  EXPECT_FLOAT_EQ(box->patches[0].extent(), 1.0f);
  EXPECT_NEAR(box->patches[0].variance(), 0.25f, 1e-6);
}

TEST(MlsMap, GapClosedByNewPointsMergesPatches) {
  MlsMap map;
  map.insert(std::vector<Eigen::Vector3f>{{0.5f, 0.5f, 0.0f}, {0.5f, 0.5f, 2.0f}});
  ASSERT_EQ(map.cell({0, 0})->size, 2);
  map.insert(std::vector<Eigen::Vector3f>{{0.5f, 0.5f, 1.0f}});
  const MlsCell* c = map.cell({0, 0});
  ASSERT_EQ(c->size, 1);
  EXPECT_EQ(c->patches[0].count, 3u);
  EXPECT_NEAR(c->patches[0].mean_z, 1.0f, 1e-6);
  EXPECT_NEAR(c->patches[0].variance(), 1.0f, 1e-6);
}

TEST(MlsMap, GrowsInEveryDirectionIncludingNegativeCells) {
  MlsMap map;
  map.insert(std::vector<Eigen::Vector3f>{{-1000.5f, -0.1f, 0.0f}, {2000.2f, 5000.9f, 1.0f}});
  EXPECT_NE(map.cell({-1001, -1}), nullptr);
  EXPECT_NE(map.cell({2000, 5000}), nullptr);
  const auto ext = map.extent();
  ASSERT_TRUE(ext);
  EXPECT_EQ(ext->first, (CellIndex{-1001, -1}));
  EXPECT_EQ(ext->second, (CellIndex{2000, 5000}));
  EXPECT_EQ(map.occupied_cells(), 2u);
}

TEST(MlsMap, NonFinitePointsAreRefusedAndTheMapStaysIntact) {
  MlsMap map;
  map.insert(slab(0, 3, 0, 3, 0.0f));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const InsertStats st = map.insert(std::vector<Eigen::Vector3f>{{nan, 0.5f, 0.0f},
                                                                 {0.5f, inf, 0.0f},
                                                                 {0.5f, 0.5f, nan},
                                                                 {0.5f, 0.5f, -inf},
                                                                 {1e30f, 0, 0},
                                                                 {1.5f, 1.5f, 0.01f}});
  EXPECT_EQ(st.rejected, 5u);
  EXPECT_EQ(st.inserted, 1u);
  EXPECT_EQ(map.occupied_cells(), 9u);
  const MlsCell* c = map.cell({0, 0});
  ASSERT_EQ(c->size, 1);
  EXPECT_EQ(c->patches[0].count, 4u);
  EXPECT_TRUE(std::isfinite(c->patches[0].mean_z));
}

TEST(RegionSegmentation, AreasMatchAHandCount) {
  MlsMap map;
  // Data on x 0..29, y 0..9 (300 cells); the target is x 0..39, y 0..9 (400 cells).
  map.insert(slab(0, 30, 0, 10, 0.0f));
  const auto target = TargetRegion::rectangle({0, 0}, {40, 10});
  // One scan point at (0.5, 0.5): cell centres (i + 0.5, j + 0.5) lie within 20 m when
  // i² + j² < 400, i.e. for j = 0..9: i ≤ 19, 19, 19, 19, 19, 19, 19, 18, 18, 17 → 196 cells.
  const RegionMap r = segment_regions(map, target, {{0.5, 0.5}});
  EXPECT_EQ(r.completed, 196u);
  EXPECT_EQ(r.low_resolution, 300u - 196u);
  EXPECT_EQ(r.unscanned, 100u);
  EXPECT_DOUBLE_EQ(r.detected_m2(), 300.0);
  EXPECT_EQ(r.at({19, 0}), Region::kCompleted);
  EXPECT_EQ(r.at({20, 0}), Region::kLowResolution);
  EXPECT_EQ(r.at({35, 5}), Region::kUnscanned);
  EXPECT_EQ(r.at({45, 5}), Region::kOutside);
}

TEST(RegionSegmentation, PolygonTargetCountsOnlyCellsWhoseCentreIsInside) {
  MlsMap map;
  map.insert(slab(0, 10, 0, 10, 0.0f));
  // A right triangle with legs of 10 m: cell (i, j) is in when its centre is, i + j + 1 ≤ 10
  // (centres on the hypotenuse count as inside) → 55 cells.
  const auto target = TargetRegion::polygon({{0, 0}, {10, 0}, {0, 10}});
  const RegionMap r = segment_regions(map, target, {{0, 0}});
  EXPECT_EQ(r.completed + r.low_resolution + r.unscanned, 55u);
}

TEST(MovableRegion, StepIsNotCrossedButARampIs) {
  MlsMap map;
  map.insert(slab(0, 10, 0, 10, 0.0f));  // lower ground
  map.insert(slab(10, 20, 0, 5, 0.2f));  // a 0.2 m step up along x
  // A ramp from 0 to 0.2 m over x 10..13 along y 5..10 (0.067 m per cell), then the plaza.
  for (int x = 10; x < 13; ++x) map.insert(slab(x, x + 1, 5, 10, 0.2f * (x - 9) / 3.0f));
  map.insert(slab(13, 20, 5, 10, 0.2f));
  const MovableRegion m = movable_region(map, {2.5, 2.5, 0.0});
  EXPECT_TRUE(m.contains({5, 5}));
  EXPECT_TRUE(m.contains({11, 7})) << "on the ramp";
  EXPECT_TRUE(m.contains({15, 2})) << "the upper level, reached by the ramp";
  // Without the ramp the step alone is not climbed.
  MlsMap steps;
  steps.insert(slab(0, 10, 0, 10, 0.0f));
  steps.insert(slab(10, 20, 0, 10, 0.2f));
  const MovableRegion s = movable_region(steps, {2.5, 2.5, 0.0});
  EXPECT_TRUE(s.contains({9, 5}));
  EXPECT_FALSE(s.contains({10, 5}));
  EXPECT_EQ(s.cells, 100u);
}

// Paper Fig. 2: under a tree a DEM sees only the canopy, an MLS map also the ground below it.
TEST(MovableRegion, MlsDrivesUnderTheCanopyWhereDemIsBlocked) {
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/tree_row.json");
  const RayCaster caster(w);
  Pose at = w.start;
  at.x = 11;
  at.y = 11;
  MlsMap map;
  map.insert_scan(simulate_scan(caster, w.scanner, at, 3), at.isometry(),
                  {0, 0, w.scanner.mount_height_m});
  const CellIndex under = map.index_of(12.5, 15.5);  // 1.5 m beside the second tree's trunk
  const MlsCell* cell = map.cell(under);
  ASSERT_NE(cell, nullptr);
  ASSERT_GE(cell->size, 2) << "ground and canopy are two surfaces";
  const Eigen::Vector3d robot(at.x, at.y, at.z);
  EXPECT_TRUE(movable_region(map, robot).contains(under));
  MovableConfig dem;
  dem.surfaces = MovableConfig::Surfaces::kDem;
  EXPECT_FALSE(movable_region(map, robot, dem).contains(under));
}

TEST(MlsMap, FillingBetweenBeamsClosesTheRingsOfFarGround) {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json");
  const RayCaster caster(w);
  const PointCloud scan = simulate_scan(caster, w.scanner, w.start, 1);
  MlsConfig plain_config;
  plain_config.fill_between_beams = false;
  MlsMap plain(plain_config), filled;
  const Eigen::Vector3d sensor(0, 0, w.scanner.mount_height_m);
  plain.insert_scan(scan, w.start.isometry(), sensor);
  filled.insert_scan(scan, w.start.isometry(), sensor);
  // Open ground 12..16 m east and 3..9 m south of the start: rings only without filling.
  std::size_t plain_cells = 0, filled_cells = 0;
  for (int dx = 12; dx < 16; ++dx) {
    for (int dy = -9; dy <= -3; ++dy) {
      const CellIndex c = plain.index_of(w.start.x + dx, w.start.y + dy);
      plain_cells += plain.cell(c) != nullptr;
      if (const MlsCell* f = filled.cell(c)) {
        ++filled_cells;
        EXPECT_NEAR(f->patches[0].mean_z, 0.0, 0.05);
      }
    }
  }
  EXPECT_LT(plain_cells, 20u);
  EXPECT_EQ(filled_cells, 28u);
}

TEST(MlsMap, AMeasurementReplacesTheHeightsInterpolatedBetweenBeams) {
  // Two returns of one fan, 10 m and 14 m out: the ground between them is interpolated, rising
  // from -1 m to -0.2 m as it would towards the top of a low wall.
  PointCloud fan;
  fan.points = {{10.2f, 0.51f, -1.0f}, {14.2f, 0.71f, -0.2f}};  // one azimuth
  MlsMap map;
  map.insert_scan(fan, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero());
  const MlsCell* guessed = map.cell({12, 0});
  ASSERT_NE(guessed, nullptr);
  EXPECT_TRUE(guessed->interpolated);
  EXPECT_NEAR(guessed->patches[0].mean_z, -0.6f, 0.15f);
  // A later scan measures the real ground there, 0.4 m below the guess: the cell becomes that
  // ground alone, one thin patch, not a 0.4 m deep mix that is no floor.
  map.insert(std::vector<Eigen::Vector3f>{{12.5f, 0.5f, -1.0f}, {12.7f, 0.2f, -1.01f}});
  const MlsCell* measured = map.cell({12, 0});
  ASSERT_NE(measured, nullptr);
  EXPECT_FALSE(measured->interpolated);
  ASSERT_EQ(measured->size, 1);
  EXPECT_EQ(measured->patches[0].count, 2u);
  EXPECT_NEAR(measured->patches[0].extent(), 0.01f, 1e-4f);
  // Interpolated cells never overwrite measured ones, and measured ones are never reset.
  map.insert_scan(fan, Eigen::Isometry3d::Identity(), Eigen::Vector3d::Zero());
  EXPECT_EQ(map.cell({12, 0})->patches[0].count, 2u);
  map.insert(std::vector<Eigen::Vector3f>{{12.5f, 0.5f, -0.99f}});
  EXPECT_EQ(map.cell({12, 0})->patches[0].count, 3u);
  EXPECT_TRUE(map.cell({11, 0})->interpolated);
}

TEST(TopView, LayersHaveTheTargetsShapeAndColours) {
  MlsMap map;
  map.insert(slab(0, 30, 0, 10, 0.0f));
  const RegionMap r = segment_regions(map, TargetRegion::rectangle({0, 0}, {40, 10}), {{0.5, 0.5}});
  const MovableRegion m = movable_region(map, {0.5, 0.5, 0.0});
  TopViewStyle style;
  style.px_per_cell = 2;
  const cv::Mat img = render_regions(r, &m, {{0.5, 0.5}}, style);
  EXPECT_EQ(img.cols, r.cells.cols * 2);
  EXPECT_EQ(img.rows, r.cells.rows * 2);
  // Cell (25, 5): low resolution and movable → yellow (BGR 64, 208, 236); north is up.
  const cv::Vec3b px = img.at<cv::Vec3b>((r.cells.rows - 1 - 5) * 2, 25 * 2);
  EXPECT_EQ(px, cv::Vec3b(64, 208, 236));
  const auto png = encode_png(render_elevation(map, r, style));
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png[1], 'P');
  EXPECT_EQ(encode_png(render_movable(map, m, r, style))[2], 'N');
}

}  // namespace
}  // namespace scanplan

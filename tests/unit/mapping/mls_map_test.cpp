#include <gtest/gtest.h>

#include "mapping_test_support.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

using test::slab;

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

}  // namespace
}  // namespace scanplan

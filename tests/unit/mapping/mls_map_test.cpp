#include <gtest/gtest.h>

#include <cmath>

#include "mapping_test_support.hpp"
#include "same_map.hpp"
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

// Sector b holds the directions [22.5° b, 22.5° (b + 1)) from the x axis.
TEST(MlsMap, ViewSectorsSplitTheCircleIntoSixteen) {
  for (int b = 0; b < kViewSectors; ++b) {
    for (const double within : {0.05, 0.5, 0.95}) {
      const double a = (b + within) * 2 * M_PI / kViewSectors;
      EXPECT_EQ(view_sector(static_cast<float>(std::cos(a)), static_cast<float>(std::sin(a))), b)
          << "at " << a * 180 / M_PI << "°";
    }
  }
}

// A wall keeps the side it was measured from: the planner's forecast of a match counts it only
// for a scan on that side (RegistrabilityField).
TEST(MlsMap, SurfacesKeepTheDirectionsTheyWereMeasuredFrom) {
  MlsMap map;
  std::vector<Eigen::Vector3f> wall;
  for (float z = 0; z <= 3; z += 0.25f) wall.emplace_back(10.5f, 0.5f, z);
  map.insert(wall, Eigen::Vector2d(0.5, 0.0));  // from the west: the direction back is ~183°
  const MlsCell* c = map.cell({10, 0});
  ASSERT_NE(c, nullptr);
  ASSERT_EQ(c->size, 1);
  EXPECT_EQ(c->patches[0].seen_from, ViewSectors{1} << 8);
  map.insert(wall, Eigen::Vector2d(10.0, 20.5));  // and from the north: ~91°
  EXPECT_EQ(map.cell({10, 0})->patches[0].seen_from, (ViewSectors{1} << 8) | (ViewSectors{1} << 4));
  // A scan carries its scanner with it; points without one are seen from anywhere.
  PointCloud scan;
  for (const Eigen::Vector3f& p : wall) scan.push_back(p - Eigen::Vector3f(30, 0.5f, 0), {1, 1, 1});
  map.insert_scan(scan, Eigen::Isometry3d(Eigen::Translation3d(30, 0.5, 0)),
                  Eigen::Vector3d(0, 0, 1));  // from the east: 0°
  EXPECT_EQ(map.cell({10, 0})->patches[0].seen_from,
            (ViewSectors{1} << 8) | (ViewSectors{1} << 4) | ViewSectors{1});
  map.insert(std::vector<Eigen::Vector3f>{{20.5f, 0.5f, 0}});
  EXPECT_EQ(map.cell({20, 0})->patches[0].seen_from, 0);
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

// A scan that moved is taken out and put back where it now lies by emptying the tiles it lay and
// lies in and inserting, restricted to them, every scan that reaches them in the order they came:
// the map is then what the scans at their new poses make from scratch, cell for cell, and the
// tiles farther away were not touched.
TEST(MlsMap, ClearedTilesFilledAgainAreTheMapTheScansMakeFromScratch) {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  w.scanner.rotation_step_deg = 2.0;
  const RayCaster caster(w);
  const Eigen::Vector3d sensor(0, 0, w.scanner.mount_height_m);
  // Four scans across the campus, each kept within 25 m so that the map has tiles one scan alone
  // reaches; in the map frame, in measuring order.
  struct Placed {
    PointCloud in_map;
    Pose at;
  };
  const auto scan_at = [&](double x, double y, double yaw_deg, std::uint64_t seed) {
    Pose at = w.start;
    at.x = x, at.y = y, at.z = w.ground_height(x, y), at.yaw = deg2rad(yaw_deg);
    const PointCloud own = simulate_scan(caster, w.scanner, at, seed);
    Placed p{{}, at};
    const Eigen::Isometry3f T = at.isometry().cast<float>();
    for (const Eigen::Vector3f& q : own.points) {
      if (std::hypot(q.x(), q.y()) < 25) p.in_map.push_back(T * q, {1, 2, 3});
    }
    return p;
  };
  std::vector<Placed> scans = {scan_at(40, 60, 0, 1), scan_at(80, 45, 10, 2),
                               scan_at(150, 90, 0, 3), scan_at(120, 10, 0, 4)};
  MlsMap map;
  for (const Placed& s : scans)
    map.insert_placed_scan(s.in_map, s.at.isometry(), s.at.isometry(), sensor);
  const CellIndex far = map.index_of(170, 95);
  const MlsCell* far_before = map.cell(far);
  ASSERT_NE(far_before, nullptr);

  // The second scan moves 0.36 m and 1°.
  MlsMap::Tiles changed = map.tiles();
  changed.add(bounds_of(scans[1].in_map));
  Placed moved = scans[1];
  moved.at.x += 0.3, moved.at.y -= 0.2, moved.at.yaw += deg2rad(1.0);
  const Eigen::Isometry3f shift =
      (moved.at.isometry() * scans[1].at.isometry().inverse()).cast<float>();
  for (Eigen::Vector3f& q : moved.in_map.points) q = shift * q;
  changed.add(bounds_of(moved.in_map));
  scans[1] = moved;
  const std::size_t before = map.occupied_cells();
  map.clear(changed);
  EXPECT_LT(map.occupied_cells(), before / 2) << "most of the map lay in the changed tiles";
  EXPECT_EQ(map.cell(map.index_of(80, 45)), nullptr);
  EXPECT_EQ(map.cell(far), far_before) << "a tile only the third scan reaches stays as it was";
  std::size_t reinserted = 0;
  for (const Placed& s : scans) {
    if (!changed.reaches(bounds_of(s.in_map))) continue;
    map.insert_placed_scan(s.in_map, s.at.isometry(), s.at.isometry(), sensor, &changed);
    ++reinserted;
  }
  EXPECT_EQ(reinserted, 4u) << "each scan reaches the tiles the second one lay or lies in";
  EXPECT_EQ(map.cell(far), far_before);

  MlsMap scratch;
  for (const Placed& s : scans)
    scratch.insert_placed_scan(s.in_map, s.at.isometry(), s.at.isometry(), sensor);
  EXPECT_TRUE(testing_support::same_map(map, scratch));
  EXPECT_TRUE(testing_support::same_map(scratch, map));

  // The same tiles filled in two halves, each in a map of its own (as two threads do), and
  // taken over: the same map again.
  const auto [west, east] = changed.halves();
  EXPECT_FALSE(west.empty());
  EXPECT_FALSE(east.empty());
  map.clear(changed);
  for (const MlsMap::Tiles* half : {&west, &east}) {
    MlsMap part;
    for (const Placed& s : scans) {
      if (half->reaches(bounds_of(s.in_map))) {
        part.insert_placed_scan(s.in_map, s.at.isometry(), s.at.isometry(), sensor, half);
      }
    }
    map.adopt(std::move(part));
  }
  EXPECT_TRUE(testing_support::same_map(map, scratch));
  EXPECT_TRUE(testing_support::same_map(scratch, map));
}

// A scan kept in the map frame goes in as the same scan in its own frame does: the beams that
// share a fan are still told in the scan's frame, so the ground between them is filled alike.
TEST(MlsMap, AScanInTheMapFrameFillsTheGroundAsInItsOwnFrame) {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json");
  const RayCaster caster(w);
  Pose at = w.start;
  at.yaw = deg2rad(30);
  at.roll = deg2rad(2);
  const PointCloud own = simulate_scan(caster, w.scanner, at, 1);
  const Eigen::Vector3d sensor(0, 0, w.scanner.mount_height_m);
  PointCloud in_map;
  const Eigen::Isometry3f T = at.isometry().cast<float>();
  for (const Eigen::Vector3f& q : own.points) in_map.push_back(T * q, {1, 2, 3});
  MlsMap from_own, from_map;
  from_own.insert_scan(own, at.isometry(), sensor);
  from_map.insert_placed_scan(in_map, at.isometry(), at.isometry(), sensor);
  std::size_t filled = 0;
  from_own.for_each_cell([&](CellIndex, const MlsCell& c) { filled += c.interpolated; });
  EXPECT_GT(filled, 100u);
  EXPECT_TRUE(testing_support::same_map(from_map, from_own));
}

}  // namespace
}  // namespace scanplan

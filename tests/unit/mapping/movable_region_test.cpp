#include <gtest/gtest.h>

#include "mapping_test_support.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

using test::slab;

TEST(MovableRegion, StepIsNotCrossedButARampIs) {
  MlsMap map;
  map.insert(slab(0, 10, 0, 10, 0.0f));  // lower ground
  map.insert(slab(10, 20, 0, 5, 0.2f));  // a 0.2 m step up along x
  // A ramp from 0 to 0.2 m over x 10..13 along y 5..10 (0.067 m per cell), then the plaza.
  for (int x = 10; x < 13; ++x)
    map.insert(slab(x, x + 1, 5, 10, 0.2f * static_cast<float>(x - 9) / 3.0f));
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

}  // namespace
}  // namespace scanplan

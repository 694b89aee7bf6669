#include "scanplan/planning/travel_map.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "mapping/mapping_test_support.hpp"

namespace scanplan {
namespace {

using test::slab;

TEST(TravelMap, StraightStepsCostACellDiagonalsRootTwo) {
  MlsMap map;
  map.insert(slab(0, 20, 0, 20, 0.0f));
  const Eigen::Vector3d robot(2.5, 2.5, 0);
  const MovableRegion movable = movable_region(map, robot);
  const TravelMap t = travel_map(map, movable, robot, {});
  EXPECT_EQ(t.start, (CellIndex{2, 2}));
  EXPECT_DOUBLE_EQ(t.distance({2, 2}), 0.0);
  EXPECT_NEAR(t.distance({12, 2}), 10.0, 1e-5);
  EXPECT_NEAR(t.distance({12, 12}), 10 * std::sqrt(2.0), 1e-4);
  EXPECT_NEAR(t.distance({12, 7}), 5 + 5 * std::sqrt(2.0), 1e-4);
  const auto path = t.path_to({12, 7});
  ASSERT_EQ(path.size(), 11u);
  EXPECT_EQ(path.front(), Eigen::Vector2d(2.5, 2.5));
  EXPECT_EQ(path.back(), Eigen::Vector2d(12.5, 7.5));
  EXPECT_FALSE(t.reachable({30, 30}));
  EXPECT_TRUE(t.path_to({30, 30}).empty());
}

TEST(TravelMap, GoesRoundAWallAndNotUpAStep) {
  MlsMap map;
  map.insert(slab(0, 20, 0, 20, 0.0f));
  // A wall at x = 10 from y = 0 to 15: the way from (5, 5) to (15, 5) goes round its end.
  for (int y = 0; y < 15; ++y) {
    for (float z = 0; z <= 2.0f; z += 0.25f)
      map.insert(std::vector<Eigen::Vector3f>{{10.5f, static_cast<float>(y) + 0.5f, z}});
  }
  // A platform 0.2 m up beyond x = 20, higher than the robot climbs.
  map.insert(slab(20, 25, 0, 20, 0.2f));
  const Eigen::Vector3d robot(5.5, 5.5, 0);
  const MovableRegion movable = movable_region(map, robot);
  const TravelMap t = travel_map(map, movable, robot, {});
  EXPECT_GT(t.distance({15, 5}), 20.0) << "round the wall's end at y = 15";
  EXPECT_FALSE(t.reachable({22, 5}));
  // Kept within a target region, the way round leaves it and nothing behind the wall is reached.
  const TargetRegion below = TargetRegion::rectangle({0, 0}, {20, 14});
  const TravelMap inside = travel_map(map, movable, robot, {}, &below);
  EXPECT_FALSE(inside.reachable({15, 5}));
  EXPECT_TRUE(inside.reachable({5, 12}));
}

// The server's default region is a 200 m square around the first scan. A robot standing 2 m past
// its edge (driven there by hand, or by a planner that knew a larger region) got no candidate at
// all: the way back in lay outside the region too (server_bench's scan 20).
TEST(TravelMap, ARobotOutsideTheRegionDrivesIntoIt) {
  MlsMap map;
  map.insert(slab(0, 30, 0, 20, 0.0f));
  const TargetRegion region = TargetRegion::rectangle({0, 0}, {20, 20});
  const Eigen::Vector3d robot(25.5, 5.5, 0);
  const MovableRegion movable = movable_region(map, robot);
  const TravelMap t = travel_map(map, movable, robot, {}, &region);
  EXPECT_NEAR(t.distance({15, 5}), 10.0, 1e-5);
  EXPECT_TRUE(t.reachable({2, 18}));
  // From inside, the drive keeps to the region.
  const TravelMap in = travel_map(map, movable, {15.5, 5.5, 0}, {}, &region);
  EXPECT_FALSE(in.reachable({25, 5}));
  EXPECT_TRUE(in.reachable({2, 18}));
  // The no-go zones hold all the same: one across the way in from x = 21 to 23, y up to 15,
  // makes the drive go round its end.
  const std::vector<TargetRegion> no_go{TargetRegion::rectangle({21, 0}, {23, 15})};
  const TravelMap round = travel_map(map, movable, robot, {}, &region, no_go);
  EXPECT_GT(round.distance({15, 5}), 20.0);
  EXPECT_FALSE(round.reachable({22, 5}));
}

}  // namespace
}  // namespace scanplan

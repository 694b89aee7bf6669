#include <gtest/gtest.h>

#include "scanplan/sim/world_traversability.hpp"

namespace scanplan {
namespace {

class TreeRow : public ::testing::Test {
 protected:
  TreeRow()
      : world_(load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/tree_row.json")),
        caster_(world_),
        trav_(world_, caster_),
        reach_(trav_.reach_from(world_.start.x, world_.start.y, world_.start.z)) {}

  bool reachable(double x, double y) const { return reach_.reachable(*trav_.cell_of(x, y)); }
  float reached_z(double x, double y) const { return reach_.z[*trav_.cell_of(x, y)]; }

  World world_;
  RayCaster caster_;
  WorldTraversability trav_;
  WorldTraversability::Reach reach_;
};

TEST_F(TreeRow, GroundUnderACanopyIsDrivable) {
  // Canopy bottom at 3 m, 1 m beside the trunk: the robot (1.6 m) fits under it, and what it
  // reaches there is the ground, not the canopy's top.
  EXPECT_TRUE(reachable(9.2, 15.1));
  EXPECT_NEAR(reached_z(9.2, 15.1), 0.0, 1e-6);
  const auto& layers = trav_.surfaces(*trav_.cell_of(9.2, 15.1));
  ASSERT_EQ(layers.size(), 2u) << "canopy top and ground";
  EXPECT_GT(layers[0], 4.0f);
}

TEST(WorldTraversability, LowCanopyBlocksTheRobot) {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/tree_row.json");
  for (auto& t : w.trees) t.trunk_height_m = 1.0;  // canopy bottom at 1 m: no headroom
  const RayCaster c(w);
  const WorldTraversability t(w, c);
  const auto reach = t.reach_from(w.start.x, w.start.y, w.start.z);
  EXPECT_FALSE(reach.reachable(*t.cell_of(9.2, 15.1)));
}

TEST_F(TreeRow, StepIsNotClimbedButTheRampLeadsUpIt) {
  // The 0.2 m plaza (y ≥ 24) is reached only over the ramp at x 20..24 (rising along y).
  EXPECT_TRUE(reachable(5, 27));
  EXPECT_NEAR(reached_z(5, 27), 0.2, 1e-5);
  const std::size_t plaza = *trav_.cell_of(5, 27);
  const auto path = reach_.path_to(plaza);
  ASSERT_FALSE(path.empty());
  bool via_ramp = false;
  for (std::size_t c : path) {
    const Eigen::Vector2d p = trav_.cell_center(c);
    via_ramp |= p.x() > 20 && p.x() < 24 && p.y() > 21 && p.y() < 24;
  }
  EXPECT_TRUE(via_ramp) << "the only way up is the ramp";
  // Straight up the step from below is 3 m; around by the ramp is far longer.
  EXPECT_GT(reach_.distance_m[plaza], 30.0);
}

TEST_F(TreeRow, WallsAndBoxesAreNotDrivable) {
  EXPECT_FALSE(reachable(30.15, 10));  // inside the wall
  EXPECT_FALSE(reachable(35, 14));     // on the 1 m box
  EXPECT_TRUE(reachable(38, 14));      // behind the wall, around its ends
}

TEST_F(TreeRow, StandingPoseFollowsTheRamp) {
  // The ramp rises 0.2 m over 3 m along +y: facing +y the robot pitches nose-up.
  const Pose p = trav_.standing_pose(22, 22.5, reached_z(22, 22.5), M_PI / 2);
  EXPECT_NEAR(p.pitch, -std::atan(0.2 / 3.0), 1e-3);
  EXPECT_NEAR(p.roll, 0.0, 1e-3);
  // Facing +x across the same slope, it rolls instead.
  const Pose q = trav_.standing_pose(22, 22.5, reached_z(22, 22.5), 0);
  EXPECT_NEAR(std::abs(q.roll), std::atan(0.2 / 3.0), 1e-3);
  EXPECT_NEAR(q.pitch, 0.0, 1e-3);
  // The tilted robot's up axis is the ramp's normal.
  const Eigen::Vector3d up = q.isometry().linear() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(up.y(), -std::sin(std::atan(0.2 / 3.0)), 1e-3);
}

TEST(WorldTraversability, StartOffTheRegionIsRefused) {
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/tree_row.json");
  const RayCaster c(w);
  const WorldTraversability t(w, c);
  EXPECT_THROW(t.reach_from(-5, -5, 0), std::invalid_argument);
  EXPECT_THROW(t.reach_from(35, 14, 0), std::invalid_argument) << "on top of a box at 1 m";
}

}  // namespace
}  // namespace scanplan

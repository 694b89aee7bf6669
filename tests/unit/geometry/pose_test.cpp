#include "scanplan/geometry/pose.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace scanplan {
namespace {

TEST(PoseChange, DistanceIn3DAndTheShorterTurnEitherWay) {
  const Pose from{.x = 1, .y = 2, .z = 0.5, .yaw = deg2rad(179)};
  const Pose to{.x = 4, .y = 6, .z = 0.5 + 12, .yaw = deg2rad(-178)};
  const PoseChange d = pose_change(from, to);
  EXPECT_NEAR(d.metres, 13, 1e-12);
  // 179° to −178° is 3° across ±180°, not 357°.
  EXPECT_NEAR(d.degrees, 3, 1e-9);
  const PoseChange back = pose_change(to, from);
  EXPECT_NEAR(back.metres, d.metres, 1e-12);
  EXPECT_NEAR(back.degrees, d.degrees, 1e-9);
  EXPECT_EQ(pose_change(to, to).metres, 0);
  EXPECT_EQ(pose_change(to, to).degrees, 0);
}

}  // namespace
}  // namespace scanplan

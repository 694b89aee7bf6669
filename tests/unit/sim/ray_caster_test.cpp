// Each solid against answers worked out by hand (in the comments), to 1e-9 m.
#include <gtest/gtest.h>

#include <cmath>

#include "scanplan/sim/ray_caster.hpp"

namespace scanplan {
namespace {

constexpr double kTol = 1e-9;

World empty_world(double ground_z = 0) {
  World w;
  w.bounds_min = {-100, -100};
  w.bounds_max = {100, 100};
  w.ground_z = ground_z;
  return w;
}

// Casts and checks what every hit must satisfy: a unit normal facing the ray.
std::optional<RayHit> cast(const World& w, const Eigen::Vector3d& origin,
                           const Eigen::Vector3d& dir, double min_range = 0,
                           double max_range = 1000) {
  const auto hit = RayCaster(w).cast(origin, dir.normalized(), min_range, max_range);
  if (hit) {
    EXPECT_NEAR(hit->normal.norm(), 1.0, 1e-6);
    EXPECT_LE(hit->normal.cast<double>().dot(dir.normalized()), 1e-6) << "normal faces away";
  }
  return hit;
}

void expect_normal(const RayHit& hit, const Eigen::Vector3d& expected) {
  EXPECT_TRUE(hit.normal.isApprox(expected.normalized().cast<float>(), 1e-5f))
      << "normal " << hit.normal.transpose() << ", expected " << expected.normalized().transpose();
}

TEST(RayCasterBox, YawedBoxIsEnteredThroughItsTurnedFace) {
  World w = empty_world();
  // Centre (10, 0, 1), half extents (1, 2, 1), turned 30°. A ray along +x from (0, 0, 1) is,
  // in the box frame, (cos30, −sin30) from (−10cos30, 10sin30); it enters the x = −1 face at
  // t = (10cos30 − 1)/cos30 = 10 − 1/cos30 (the y slab is entered earlier, at t = 6).
  w.boxes.push_back({{9, -2, 0}, {11, 2, 2}, deg2rad(30), {9, 8, 7}});
  const auto hit = cast(w, {0, 0, 1}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10 - 1 / std::cos(deg2rad(30)), kTol);
  EXPECT_EQ(hit->color, (Rgb{9, 8, 7}));
  expect_normal(*hit, {-std::cos(deg2rad(30)), -std::sin(deg2rad(30)), 0});
}

TEST(RayCasterBox, FromInsideTheInnerWallIsSeen) {
  World w = empty_world(-10);
  w.boxes.push_back({{-1, -1, -1}, {1, 1, 1}, deg2rad(10), {1, 1, 1}});
  const auto hit = cast(w, {0, 0, 0}, {0, 0, 1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 1.0, kTol);
  expect_normal(*hit, {0, 0, -1});
}

TEST(RayCasterCylinder, SideCapAndInside) {
  World w = empty_world();
  w.cylinders.push_back({{5, 0}, 0, 3, 1, {4, 5, 6}});
  // Side, straight on: the circle x = 4.
  auto hit = cast(w, {0, 0, 1}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 4.0, kTol);
  EXPECT_EQ(hit->color, (Rgb{4, 5, 6}));
  expect_normal(*hit, {-1, 0, 0});
  // Side, off-centre at y = 0.6: x = 5 − √(1 − 0.36) = 4.2, normal (−0.8, 0.6, 0).
  hit = cast(w, {0, 0.6, 1}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 4.2, kTol);
  expect_normal(*hit, {-0.8, 0.6, 0});
  // Top cap from above: z = 3 from z = 10.
  hit = cast(w, {5, 0.5, 10}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 7.0, kTol);
  expect_normal(*hit, {0, 0, 1});
  // Oblique onto the cap: from (3, 0, 5) along (1, 0, −1) it reaches z = 3 at (5, 0), the
  // cap's centre, after 2√2; at x = 4 it is still at z = 4, above the rim.
  hit = cast(w, {3, 0, 5}, {1, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 2 * std::sqrt(2.0), kTol);
  expect_normal(*hit, {0, 0, 1});
  // From inside: the wall 1 m away, seen from within.
  hit = cast(w, {5, 0, 1}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 1.0, kTol);
  expect_normal(*hit, {-1, 0, 0});
  // Over the top and past it: nothing.
  EXPECT_FALSE(cast(w, {0, 0, 3.5}, {1, 0, 0}));
}

TEST(RayCasterEllipsoid, ScaledSphere) {
  World w = empty_world();
  w.ellipsoids.push_back({{10, 0, 2}, {2, 1, 0.5}, {7, 7, 7}});
  auto hit = cast(w, {0, 0, 2}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 8.0, kTol);
  expect_normal(*hit, {-1, 0, 0});
  hit = cast(w, {10, 0, 10}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 7.5, kTol);
  // Along +y at x = 10, z = 2.2: y² = 1 − (0.2/0.5)² = 0.84, entry y = −√0.84; the gradient
  // ((x−10)/4, y, (z−2)/0.25) there is (0, −√0.84, 0.8).
  hit = cast(w, {10, -3, 2.2}, {0, 1, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 3 - std::sqrt(0.84), kTol);
  expect_normal(*hit, {0, -std::sqrt(0.84), 0.8});
}

TEST(RayCasterTree, TrunkBelowTheCanopyCanopyAbove) {
  World w = empty_world();
  // Canopy centre at z = 3 + 2 = 5; its bottom is at z = 3.
  w.trees.push_back({{20, 0, 0}, 0.3, 3.0, {2.5, 2.5, 2.0}, {0, 200, 0}, {100, 50, 0}});
  // 1 m under the canopy a horizontal ray meets the trunk only…
  auto hit = cast(w, {10, 0, 2}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10 - 0.3, kTol);
  EXPECT_EQ(hit->color, (Rgb{100, 50, 0}));
  // …and once past the trunk (nearer than min_range) there is nothing more: not the canopy.
  EXPECT_FALSE(cast(w, {10, 0, 2}, {1, 0, 0}, 10.5));
  // Beside the trunk the ray passes under the canopy untouched.
  EXPECT_FALSE(cast(w, {10, 1.0, 2}, {1, 0, 0}));
  // Through the canopy's centre height: its side at x = 17.5.
  hit = cast(w, {10, 0, 5}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 7.5, kTol);
  EXPECT_EQ(hit->color, (Rgb{0, 200, 0}));
  // Straight up at 1 m from the trunk axis: the underside at z = 5 − 2·√(1 − (1/2.5)²).
  hit = cast(w, {20, 1, 0.5}, {0, 0, 1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 4.5 - 2 * std::sqrt(0.84), kTol);
  expect_normal(*hit, {0, 1 / 6.25, -std::sqrt(0.84) / 2});
}

TEST(RayCasterRamp, TopRisesLinearlyWallsBelow) {
  World w = empty_world();
  w.ramps.push_back({{0, 0, 0}, {10, 4, 1}, 0, {3, 3, 3}});    // top z = 0.1·x
  w.ramps.push_back({{20, 0, 0}, {24, 10, 2}, 1, {4, 4, 4}});  // top z = 0.2·y
  EXPECT_NEAR(w.ramps[0].top_z(6, 2), 0.6, kTol);
  EXPECT_NEAR(w.ramps[1].top_z(22, 7), 1.4, kTol);
  // Straight down onto the slope.
  auto hit = cast(w, {6, 2, 5}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 5 - 0.6, kTol);
  EXPECT_EQ(hit->color, (Rgb{3, 3, 3}));
  expect_normal(*hit, {-0.1, 0, 1});
  hit = cast(w, {22, 7, 5}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 5 - 1.4, kTol);
  expect_normal(*hit, {0, -0.2, 1});
  // Level at z = 0.5 from the low end: the slope rises to meet it at x = 5.
  hit = cast(w, {-5, 2, 0.5}, {1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10.0, kTol);
  // From the high end: the vertical wall at x = 10.
  hit = cast(w, {15, 2, 0.5}, {-1, 0, 0});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 5.0, kTol);
  expect_normal(*hit, {1, 0, 0});
  // Above the top at the high end: nothing.
  EXPECT_FALSE(cast(w, {15, 2, 1.2}, {-1, 0, 0}));
}

World grid_world() {
  World w = empty_world();
  // Nodes 2 m apart: row 0 (y = 0) 0, 1, 3; row 1 (y = 2) 0.5, 2, 2.
  w.ground_grid.emplace(Eigen::Vector2d(0, 0), 2.0, 3, 2, std::vector<double>{0, 1, 3, 0.5, 2, 2});
  w.ground_color = {11, 12, 13};
  return w;
}

TEST(GroundGrid, BilinearHeightsClampedOutside) {
  const World w = grid_world();
  EXPECT_NEAR(w.ground_height(1, 1), (0 + 1 + 0.5 + 2) / 4.0, kTol);
  // Cell 1 at u = 0.5, v = 0.25: 1·.375 + 3·.375 + 2·.125 + 2·.125.
  EXPECT_NEAR(w.ground_height(3, 0.5), 2.0, kTol);
  EXPECT_NEAR(w.ground_height(4, 2), 2.0, kTol);
  EXPECT_NEAR(w.ground_height(-5, 1), 0.25, kTol) << "west of the grid: column 0";
  EXPECT_NEAR(w.ground_height(5, 1), 2.5, kTol) << "east of the grid: column 2";
  EXPECT_NEAR(w.ground_height(10, 10), 2.0, kTol) << "beyond a corner: the corner node";
  EXPECT_NEAR(w.ground_height(10, -3), 3.0, kTol);
}

TEST(GroundGrid, RaysComeDownOntoTheSurface) {
  const World w = grid_world();
  auto hit = cast(w, {1, 1, 10}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10 - 0.875, kTol);
  EXPECT_EQ(hit->color, (Rgb{11, 12, 13}));
  // Along y = 1 (v = 0.5) the surface of cell 0 is h = 0.25 + 0.625·x; the ray
  // z = 1.5 − 0.5·x (from x = −1, z = 2) meets it at x = 1.25/1.125. The gradient there is
  // (0.625, (0.5 + 0.5·u)/2) with u = x/2.
  const double x = 1.25 / 1.125;
  hit = cast(w, {-1, 1, 2}, {1, 0, -0.5});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, (x + 1) * std::sqrt(1.25), kTol);
  expect_normal(*hit, {-0.625, -(0.5 + 0.25 * x) / 2, 1});
  // Beyond the grid's corner the surface is flat at the corner node's height.
  hit = cast(w, {20, 20, 5}, {0, 0, -1});
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 3.0, kTol);
  // A slanting ray across several cells lands on the surface, and is above it just before.
  const Eigen::Vector3d o(-3, -1, 4), d = Eigen::Vector3d(1, 0.4, -0.45).normalized();
  hit = cast(w, o, d);
  ASSERT_TRUE(hit);
  const Eigen::Vector3d p = o + hit->range * d;
  EXPECT_NEAR(p.z(), w.ground_height(p.x(), p.y()), kTol);
  for (double t = 0; t < hit->range - 1e-6; t += 0.01) {
    const Eigen::Vector3d q = o + t * d;
    ASSERT_GT(q.z(), w.ground_height(q.x(), q.y())) << "passed under the ground at t = " << t;
  }
  // From underneath, the ground is not seen.
  EXPECT_FALSE(cast(w, {1, 1, -1}, {0, 0, 1}));
}

TEST(RayCasterRanges, MinAndMaxRangeBoundWhatCounts) {
  World w = empty_world();
  w.boxes.push_back({{5, -1, 0}, {6, 1, 2}, 0, {1, 2, 3}});
  EXPECT_FALSE(cast(w, {0, 0, 1}, {1, 0, 0}, 0, 4.9));
  // Nearer than min_range the entry face does not count; the far wall then does.
  const auto hit = cast(w, {0, 0, 1}, {1, 0, 0}, 5.5, 100);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 6.0, kTol);
}

}  // namespace
}  // namespace scanplan

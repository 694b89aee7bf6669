// The best candidates checked against the map's own points: what a scanner there sees, and
// the ranking after the check.
#include "scanplan/mission/view_check.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "scanplan/registration/alignment_quality.hpp"

namespace scanplan {
namespace {

constexpr float kVoxel = 0.25f;

// A vertical wall across x = `x`, |y| ≤ half_width, 0 ≤ z ≤ height, sampled at kVoxel.
void add_wall_across_x(PointCloud& cloud, float x, float half_width, float height) {
  for (float y = -half_width; y <= half_width; y += kVoxel) {
    for (float z = 0; z <= height; z += kVoxel) cloud.points.emplace_back(x, y, z);
  }
}

// A vertical wall along x at y = `y`, x0 ≤ x ≤ x1.
void add_wall_along_x(PointCloud& cloud, float y, float x0, float x1, float height) {
  for (float x = x0; x <= x1; x += kVoxel) {
    for (float z = 0; z <= height; z += kVoxel) cloud.points.emplace_back(x, y, z);
  }
}

void add_ground(PointCloud& cloud, float half) {
  for (float x = -half; x <= half; x += kVoxel) {
    for (float y = -half; y <= half; y += kVoxel) cloud.points.emplace_back(x, y, 0);
  }
}

std::size_t count_near_x(const PointCloud& cloud, float x) {
  std::size_t n = 0;
  for (const auto& p : cloud.points) n += std::abs(p.x() - x) < 0.01f ? 1 : 0;
  return n;
}

TEST(VisiblePoints, ANearWallHidesTheWallBehindIt) {
  PointCloud map;
  add_wall_across_x(map, 10, 10, 6);  // the near wall, 20 m wide
  add_wall_across_x(map, 20, 8, 4);   // behind it, within its shadow
  const std::size_t near = count_near_x(map, 10);
  const PointCloud seen = visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {});
  // The near wall is seen whole: its voxels' spans leave no gap for what lies behind.
  EXPECT_EQ(count_near_x(seen, 10), near);
  EXPECT_EQ(count_near_x(seen, 20), 0u);
}

TEST(VisiblePoints, KeepsWhatIsInRangeAndOutOfTheShadow) {
  PointCloud map;
  add_wall_across_x(map, 10, 2, 3);  // a narrow pillar of wall
  add_wall_across_x(map, 20, 15, 3);
  add_wall_across_x(map, 70, 15, 3);  // beyond the range
  const PointCloud seen = visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {});
  // The pillar's shadow on the far wall is 2 × 2 × 20 / 10 = 8 m of its 30, over its whole
  // height: the rest is seen.
  std::size_t shadowed = 0, lit = 0;
  for (const auto& p : seen.points) {
    if (std::abs(p.x() - 20) > 0.01f) continue;
    ++(std::abs(p.y()) < 3.9f ? shadowed : lit);
  }
  EXPECT_EQ(shadowed, 0u);
  std::size_t lit_in_map = 0;
  for (const auto& p : map.points) {
    lit_in_map += std::abs(p.x() - 20) < 0.01f && std::abs(p.y()) > 4.1f ? 1 : 0;
  }
  EXPECT_GT(lit, lit_in_map * 9 / 10);
  EXPECT_EQ(count_near_x(seen, 70), 0u);
}

TEST(VisiblePoints, TheGroundIsSeenAsSparselyAsAScanSeesIt) {
  PointCloud map;
  add_ground(map, 20);
  const PointCloud seen = visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {});
  // Near the scanner each voxel is a bin of its own; at 15 m and more a bin of 0.5° spans
  // metres of ground at a grazing angle, and the scan returns one point in it.
  std::size_t near = 0, near_seen = 0, far = 0, far_seen = 0;
  const auto tally = [](const PointCloud& c, std::size_t& n, std::size_t& f) {
    for (const auto& p : c.points) {
      const float r = p.head<2>().norm();
      if (r > 1.5f && r < 5) ++n;
      if (r > 15 && r < 19) ++f;
    }
  };
  tally(map, near, far);
  tally(seen, near_seen, far_seen);
  EXPECT_GT(near_seen, near * 95 / 100);
  EXPECT_GT(far_seen, 0u);
  EXPECT_LT(far_seen, far / 3);
}

// A building's corner from beside its south face: the part of that face nearest the corner was
// never scanned, but its east face was, from the east. The east face is the far side of the
// building from here and hides behind the missing wall; only the viewpoints tell.
TEST(VisiblePoints, TheFarFaceOfABuildingIsNotSeenThroughAWallNotYetScanned) {
  PointCloud map;
  Viewpoints views;
  views.origins = {{0, -10, 1.5f}, {40, 20, 1.5f}};  // the south scan's, the east scan's
  add_wall_along_x(map, 3, -30, 5, 10);              // the south face, seen up to x = 5 of 10
  views.origin_of.resize(map.size(), 0);
  for (float y = 3; y <= 30; y += kVoxel) {  // the east face, x = 10, seen from the east
    for (float z = 0; z <= 10; z += kVoxel) map.points.emplace_back(10, y, z);
  }
  views.origin_of.resize(map.size(), 1);
  for (float y = 14; y <= 20; y += kVoxel) {  // a wall behind the building, seen from the south
    for (float z = 0; z <= 6; z += kVoxel) map.points.emplace_back(15, y, z);
  }
  views.origin_of.resize(map.size(), 0);
  const Eigen::Vector3f eye(7, 0, 1.5f);
  // Without the viewpoints the east face shows through the gap; with them it does not (but for
  // its corners, where the neighbours make no plane to tell a side by), and the south face's
  // points still do.
  const std::size_t through = count_near_x(visible_points(map, eye, kVoxel, 60, {}), 10);
  EXPECT_GT(through, 100u);
  const PointCloud seen = visible_points(map, eye, kVoxel, 60, {}, views);
  EXPECT_LE(count_near_x(seen, 10), 4u);
  // The far face still hides what stands behind the building.
  EXPECT_EQ(count_near_x(seen, 15), 0u);
  std::size_t south = 0;
  for (const auto& p : seen.points) south += std::abs(p.y() - 3) < 0.01f ? 1 : 0;
  EXPECT_GT(south, 100u);
  // Seen from the east, the east face is there: from near where it was seen, and from the
  // south-east, far enough round for its side to be told.
  EXPECT_GT(count_near_x(visible_points(map, {30, 8, 1.5f}, kVoxel, 60, {}, views), 10), 100u);
  EXPECT_GT(count_near_x(visible_points(map, {12, -10, 1.5f}, kVoxel, 60, {}, views), 10), 100u);
  // Viewpoints that do not describe the map (one point short) are not used.
  Viewpoints short_by_one = views;
  short_by_one.origin_of.pop_back();
  EXPECT_EQ(count_near_x(visible_points(map, eye, kVoxel, 60, {}, short_by_one), 10), through);
}

// The weakest constraint of what a scanner at the origin sees, as the matcher judges it.
double predicted(const PointCloud& map) {
  const PointCloud seen = visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {});
  return evaluate_alignment(map, seen, Eigen::Isometry3d::Identity(), Dof::k4, 1.0, 0.3)
      .weakest_constraint;
}

TEST(VisiblePoints, RefusesBinsThatAreNoAngleAndAJudgeOfOtherPoints) {
  PointCloud map;
  add_ground(map, 5);
  ViewCheckConfig config;
  for (const double bad : {0.0, -1.0, std::nan(""), 200.0}) {
    config.bin_deg = bad;
    EXPECT_THROW(visible_points(map, {0, 0, 1.5f}, kVoxel, 60, config), std::invalid_argument);
  }
  // Normals from a judge over other points would be another surface's.
  const PointCloud other = map;
  const AlignmentJudge judge(other);
  EXPECT_THROW(visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {}, {}, &judge),
               std::invalid_argument);
  const AlignmentJudge own(map);
  EXPECT_NO_THROW(visible_points(map, {0, 0, 1.5f}, kVoxel, 60, {}, {}, &own));
}

TEST(VisiblePoints, OneLongFacadeFixesThePoseWeaklyACornerFirmly) {
  PointCloud facade;
  add_ground(facade, 30);
  add_wall_along_x(facade, 3, -30, 30, 14);  // 3 m before a 60 m long, 14 m high face
  PointCloud corner = facade;
  add_wall_across_x(corner, 12, 10, 6);  // a second building, across the face
  const double weak = predicted(facade), firm = predicted(corner);
  EXPECT_LT(weak, ViewCheckConfig{}.min_constraint);
  EXPECT_GT(firm, ViewCheckConfig{}.min_constraint);
}

// The tests' own threshold, so that they read whatever the default.
ViewCheckConfig at_003() {
  ViewCheckConfig c;
  c.min_constraint = 0.03;
  return c;
}

Candidate candidate(double x, double score) {
  Candidate c;
  c.position = {x, 0, 0};
  c.f = c.score = score;
  c.registrability = Registrability{};
  return c;
}

TEST(CheckViews, ACandidateTheCheckFailsFallsBehindAndTheNextIsChecked) {
  Plan plan;
  plan.ranked = {candidate(1, 10), candidate(2, 8), candidate(3, 5)};
  int calls = 0;
  check_views(
      plan,
      [&](const Candidate& c) {
        ++calls;
        return c.position.x() == 1 ? 0.006 : 0.05;
      },
      at_003(), 0.05);
  EXPECT_EQ(calls, 2);
  ASSERT_EQ(plan.ranked.size(), 3u);
  EXPECT_EQ(plan.ranked[0].position.x(), 2);
  EXPECT_EQ(plan.ranked[1].position.x(), 3);
  EXPECT_EQ(plan.ranked[2].position.x(), 1);
  // (0.006 / 0.03)² = 0.04, below the floor: the floor's share.
  EXPECT_NEAR(plan.ranked[2].score, 10 * 0.05, 1e-9);
  EXPECT_NEAR(plan.ranked[2].registrability->factor, 0.05, 1e-9);
  EXPECT_NEAR(*plan.ranked[2].registrability->predicted_constraint, 0.006, 1e-12);
  EXPECT_NEAR(*plan.ranked[0].registrability->predicted_constraint, 0.05, 1e-12);
  EXPECT_FALSE(plan.ranked[1].registrability->predicted_constraint) << "never the best: unchecked";
}

TEST(CheckViews, AFailedCandidateStillTheBestStaysFirst) {
  Plan plan;
  plan.ranked = {candidate(1, 100), candidate(2, 1)};
  check_views(
      plan, [](const Candidate&) { return 0.024; }, at_003(), 0.05);
  // (0.024 / 0.03)² = 0.64 of 100 still beats 1; checked once.
  EXPECT_EQ(plan.ranked[0].position.x(), 1);
  EXPECT_NEAR(plan.ranked[0].score, 64, 1e-9);
  EXPECT_FALSE(plan.ranked[1].registrability->predicted_constraint);
}

TEST(CheckViews, ANegativeScoreFallsToo) {
  Plan plan;
  plan.ranked = {candidate(1, -2), candidate(2, -3)};
  check_views(
      plan, [](const Candidate& c) { return c.position.x() == 1 ? 0.0 : 1.0; }, {}, 0.05);
  EXPECT_EQ(plan.ranked[0].position.x(), 2);
  EXPECT_LT(plan.ranked[1].score, -3);
}

TEST(CheckViews, StopsAfterTheConfiguredCandidatesAndWhenOff) {
  int calls = 0;
  // Every candidate fails the check.
  const auto fails = [&calls](const Candidate&) {
    ++calls;
    return 0.0;
  };
  Plan plan;
  for (int i = 0; i < 8; ++i) plan.ranked.push_back(candidate(i, 10 - i));
  ViewCheckConfig config;
  config.candidates = 3;
  check_views(plan, fails, config, 0.05);
  EXPECT_EQ(calls, 3);
  config.enabled = false;
  Plan untouched;
  untouched.ranked = {candidate(1, 10), candidate(2, 8)};
  check_views(untouched, fails, config, 0.05);
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(untouched.ranked[0].position.x(), 1);
  EXPECT_FALSE(untouched.ranked[0].registrability->predicted_constraint);
  // Without a forecast (nothing anchored yet) nothing is checked.
  Plan unforecast;
  unforecast.ranked = {candidate(1, 10)};
  unforecast.ranked[0].registrability.reset();
  check_views(unforecast, fails, {}, 0.05);
  EXPECT_EQ(calls, 3);
}

}  // namespace
}  // namespace scanplan

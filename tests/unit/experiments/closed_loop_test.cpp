// The paper's procedure on a simulated world (§3: scan, map, plan, move, repeat), through the
// mission pipeline: coverage grows scan by scan, the robot drives to the suggestions, and with
// matching on the scans land where they were really taken.
#include <gtest/gtest.h>

#include <cmath>

#include "scanplan/experiments/closed_loop.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

World yard() {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json");
  w.scanner.rotation_step_deg = 1.0;  // quick, still matchable
  return w;
}

ClosedLoopConfig quick(int scans) {
  ClosedLoopConfig c;
  c.max_scans = scans;
  c.planner.policy = PlannerPolicy::kExhaustive;
  return c;
}

TEST(ClosedLoop, CoverageGrowsAndTheRobotDrivesToTheSuggestions) {
  World w = yard();
  w.pose_noise = PoseNoise{0, 0, 0};
  ClosedLoopConfig c = quick(3);
  c.matching.reset();
  int seen = 0;
  const LoopResult r = run_closed_loop(w, c, [&](const LoopStep& step, const MissionPipeline& m) {
    ++seen;
    EXPECT_EQ(m.mapping().scan_poses().size(), static_cast<std::size_t>(step.scan));
  });
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_EQ(seen, 3);
  EXPECT_GT(r.reachable_cells, 500u);
  for (std::size_t k = 1; k < r.steps.size(); ++k) {
    const LoopStep& before = r.steps[k - 1];
    const LoopStep& now = r.steps[k];
    ASSERT_TRUE(before.chosen) << "scan " << before.scan << " chose nowhere to go";
    // The robot scanned next where the chosen candidate was.
    const Eigen::Vector3d goal = before.candidates[*before.chosen].position;
    EXPECT_LT(std::hypot(now.true_pose.x - goal.x(), now.true_pose.y - goal.y()), 1e-6);
    EXPECT_GT(now.path_m, before.path_m);
    EXPECT_GE(now.coverage_pct, before.coverage_pct);
    EXPECT_GT(now.detected_m2, before.detected_m2);
  }
  EXPECT_EQ(r.stopped_because, "scan limit reached");
  EXPECT_FALSE(r.steps.back().chosen) << "no plan after the last scan";
}

// The suggestions are places on the map, whose frame is the first scan's reported pose, not the
// world's: the robot goes to the place the operator approved, wherever the map frame lies in
// the world. (Taken as world coordinates, a goal 100 m out in a map turned 5° lands 9 m off.)
TEST(ClosedLoop, TheRobotGoesWhereTheMapSaysNotToTheSameWorldCoordinates) {
  World w = yard();
  w.pose_noise = PoseNoise{1.0, 0.1, 8.0};
  ClosedLoopConfig c = quick(3);
  c.matching.reset();
  c.seed = 3;
  const LoopResult r = run_closed_loop(w, c);
  ASSERT_EQ(r.steps.size(), 3u);
  const Pose& first_true = r.steps[0].true_pose;
  const Pose& first_placed = r.steps[0].placed_pose;
  ASSERT_GT(std::abs(first_placed.yaw - first_true.yaw), deg2rad(0.5)) << "the map frame is turned";
  for (std::size_t k = 1; k < r.steps.size(); ++k) {
    const LoopStep& before = r.steps[k - 1];
    ASSERT_TRUE(before.chosen);
    const Eigen::Vector3d goal = before.candidates[*before.chosen].position;
    const Pose in_map = true_in_map(first_placed, first_true, r.steps[k].true_pose);
    EXPECT_LT(std::hypot(in_map.x - goal.x(), in_map.y - goal.y()), 1e-6) << "scan " << k + 1;
  }
  EXPECT_GT(r.reachable_cells, 500u);
}

// Each scan after the first is matched against the map so far; an applied correction puts it
// where it was taken (relative to the first scan, which defines the map frame), a refused one
// leaves it at the reported pose. (How many are applied in the loop is issue 15's measure.)
TEST(ClosedLoop, MatchedScansLandWhereTheyWereTakenAndRefusedOnesStayReported) {
  World w = yard();
  w.pose_noise = PoseNoise{0.5, 0.1, 3.0};
  const LoopResult r = run_closed_loop(w, quick(3));
  ASSERT_EQ(r.steps.size(), 3u);
  EXPECT_FALSE(r.steps[0].match) << "the first scan defines the map frame";
  const Pose& first_true = r.steps[0].true_pose;
  const Pose& first_placed = r.steps[0].placed_pose;
  for (std::size_t k = 1; k < r.steps.size(); ++k) {
    const LoopStep& s = r.steps[k];
    ASSERT_TRUE(s.match) << "scan " << s.scan << " was not matched";
    EXPECT_EQ(s.match_applied, s.match->converged) << "a refused correction is not converged";
    if (!s.match->converged) {
      EXPECT_EQ(s.placed_pose.x, s.reported_pose.x) << s.match->message;
      EXPECT_EQ(s.placed_pose.yaw, s.reported_pose.yaw) << s.match->message;
      continue;
    }
    // Relative to the first scan, in its frame: the map frame is its reported pose.
    const Eigen::Isometry3d placed = first_placed.isometry().inverse() * s.placed_pose.isometry();
    const Eigen::Isometry3d truth = first_true.isometry().inverse() * s.true_pose.isometry();
    const Eigen::Isometry3d error = truth.inverse() * placed;
    EXPECT_LT(error.translation().norm(), 0.10) << "scan " << s.scan;
    EXPECT_LT(rad2deg(Eigen::AngleAxisd(error.linear()).angle()), 0.5) << "scan " << s.scan;
    EXPECT_TRUE(s.match_applied);
    // The step carries the same error, as simulate reports it.
    EXPECT_NEAR(s.placed_error_m, error.translation().norm(), 1e-6);
    EXPECT_NEAR(s.placed_error_deg, rad2deg(Eigen::AngleAxisd(error.linear()).angle()), 1e-6);
  }
}

TEST(ClosedLoop, PlacedErrorIsRelativeToTheFirstScan) {
  // The whole map shifted and turned by the first scan's error has no error at all.
  Pose first_true, first_placed, truth;
  first_true.x = 10;
  first_true.yaw = deg2rad(30);
  first_placed = first_true;
  first_placed.x += 0.7;
  first_placed.y -= 0.4;
  first_placed.yaw += deg2rad(4);
  truth.x = 25;
  truth.y = 8;
  truth.yaw = deg2rad(-50);
  const Pose consistent = true_in_map(first_placed, first_true, truth);
  const PoseError none = placed_error(first_placed, first_true, consistent, truth);
  EXPECT_NEAR(none.metres, 0, 1e-9);
  EXPECT_NEAR(none.degrees, 0, 1e-6);
  EXPECT_NEAR(placed_error(first_true, first_true, truth, truth).metres, 0, 1e-12);
  // Placed where the robot really was, in a map whose frame is off by the first error: wrong
  // by that error carried 15 m along.
  const PoseError off = placed_error(first_placed, first_true, truth, truth);
  EXPECT_GT(off.metres, 0.5);
  EXPECT_NEAR(off.degrees, 4, 1e-6);
}

// The map's consistency measure: two scans placed where they were taken lie on one another's
// surfaces within the range noise (σ 1 cm); one placed 5 cm too high lies visibly off.
TEST(SurfaceDistance, OverlappingScansAtTheirPosesShareTheirSurfaces) {
  const World w = yard();
  const RayCaster caster(w);
  const auto at = [&](double x, double y) {
    Pose p;
    p.x = x;
    p.y = y;
    p.z = w.ground_height(x, y);
    return p;
  };
  const auto mission_with_second_at = [&](double dz, double dx = 0) {
    MissionConfig config;
    config.mapping.sensor_height_m = w.scanner.mount_height_m;
    config.graph.reset();  // each scan stays where it is put
    MissionPipeline mission(config);
    const Pose first = at(-15, -8), second = at(-5, -9);
    mission.add(simulate_scan(caster, w.scanner, first, 1), {first, first, true});
    Pose off = second;
    off.z += dz;
    off.x += dx;
    mission.add(simulate_scan(caster, w.scanner, second, 2), {second, off, true});
    return surface_distance(mission);
  };
  const SurfaceDistance right = mission_with_second_at(0);
  ASSERT_EQ(right.pairs, 1u);
  EXPECT_LT(right.median_m, 0.01);
  // The walls, whose normals are level, do not see a height error: the median over every
  // surface grows by a third of it (4.8 mm to 1.6 cm here).
  const SurfaceDistance high = mission_with_second_at(0.05);
  ASSERT_EQ(high.pairs, 1u);
  EXPECT_GT(high.median_m, 0.012);
  EXPECT_GT(high.median_m, 2 * right.median_m);
  // A scan 10 cm off sideways: the floor hides it (all surfaces 6 mm), the walls facing that
  // way show it (1.8 cm against 8 mm; those facing across do not).
  EXPECT_GT(right.wall_pairs, 0u);
  EXPECT_LT(right.wall_median_m, 0.01);
  const SurfaceDistance aside = mission_with_second_at(0, 0.10);
  ASSERT_EQ(aside.wall_pairs, 1u);
  EXPECT_GT(aside.wall_median_m, 0.015);
  EXPECT_GT(aside.wall_median_m, 2 * right.wall_median_m);
  RecordProperty("wall_median_right_m", std::to_string(right.wall_median_m));
  RecordProperty("wall_median_10cm_aside_m", std::to_string(aside.wall_median_m));
  RecordProperty("median_10cm_aside_m", std::to_string(aside.median_m));
  RecordProperty("median_right_m", std::to_string(right.median_m));
  RecordProperty("median_5cm_high_m", std::to_string(high.median_m));
}

}  // namespace
}  // namespace scanplan

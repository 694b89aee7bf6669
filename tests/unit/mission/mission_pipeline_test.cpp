// The paper's loop as one object: a scan is placed (matched against the map so far), mapped,
// segmented and planned from, on the yard world with known true poses.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ground_pose.hpp"
#include "same_map.hpp"
#include "scanplan/mission/mission_pipeline.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

class MissionPipelineTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new World(load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json"));
    world_->scanner.rotation_step_deg = 1.0;  // a quarter of the points: quick, still matchable
    caster_ = new RayCaster(*world_);
  }
  static void TearDownTestSuite() {
    delete caster_;
    delete world_;
  }
  static PointCloud scan_at(const Pose& truth, std::uint64_t seed) {
    return simulate_scan(*caster_, world_->scanner, truth, seed);
  }
  // A scan taken at `truth`, placed by its match to the map (reported at the truth): whether
  // the match was applied.
  static bool add_matched(MissionPipeline& mission, const Pose& truth, std::uint64_t seed) {
    const PointCloud scan = scan_at(truth, seed);
    const auto m = mission.place(scan, truth);
    if (!m || !m->applied) return false;
    Placement matched(truth, m->placed, true);
    matched.information = m->information;
    mission.add(scan, matched);
    return true;
  }
  static MissionConfig config() {
    MissionConfig c;
    c.mapping.sensor_height_m = world_->scanner.mount_height_m;
    c.planner.policy = PlannerPolicy::kExhaustive;
    return c;
  }
  static World* world_;
  static RayCaster* caster_;
};
World* MissionPipelineTest::world_ = nullptr;
RayCaster* MissionPipelineTest::caster_ = nullptr;

constexpr auto* at = &testing_support::ground_pose;

// The MLS map the scans in the mission's map make from scratch, in the order they entered it,
// each where the map holds it.
MlsMap from_scratch(const MissionPipeline& mission) {
  MlsMap map(mission.config().mapping.mls);
  const Eigen::Vector3d sensor(0, 0, mission.config().mapping.sensor_height_m);
  for (const std::size_t i : mission.map_order()) {
    map.insert_placed_scan(*mission.placed_scans()[i], mission.cloud_poses()[i].isometry(),
                           mission.map_poses()[i].isometry(), sensor);
  }
  return map;
}

TEST_F(MissionPipelineTest, TheFirstScanDefinesTheMapFrameAndIsNotMatched) {
  MissionPipeline mission(config());
  const Pose first = at(-15, -8, 0);
  const PointCloud cloud = scan_at(first, 1);
  EXPECT_FALSE(mission.place(cloud, first)) << "nothing to match against yet";
  EXPECT_FALSE(mission.has_map());
  const auto placed = mission.add(cloud, {first, first});
  ASSERT_EQ(placed->size(), cloud.size());
  EXPECT_TRUE(placed->has_colors());
  // Points go into the map frame by the pose.
  EXPECT_NEAR(placed->points[0].x(), cloud.points[0].x() + first.x, 1e-4);
  EXPECT_TRUE(mission.has_map());
  EXPECT_EQ(mission.placed_scans().size(), 1u);
  EXPECT_EQ(mission.mapping().scan_poses().size(), 1u);
  EXPECT_GT(mission.mapping().regions()->completed_m2(), 100.0);
  EXPECT_GT(mission.mapping().movable()->area_m2(), 100.0);
}

TEST_F(MissionPipelineTest, ASecondScanIsPlacedBackOnItsTruePose) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const Pose truth = at(-5, -9, 20);
  Pose reported = truth;
  reported.x += 0.6;
  reported.y -= 0.4;
  reported.yaw += deg2rad(3);
  const PointCloud second = scan_at(truth, 2);
  const auto m = mission.place(second, reported);
  ASSERT_TRUE(m);
  EXPECT_TRUE(m->applied) << m->result.message;
  EXPECT_LT(std::hypot(m->placed.x - truth.x, m->placed.y - truth.y), 0.05);
  EXPECT_LT(std::abs(rad2deg(std::remainder(m->placed.yaw - truth.yaw, 2 * M_PI))), 0.2);
  EXPECT_EQ(mission.placed_scans().size(), 1u) << "placing changes nothing";
  mission.add(second, {reported, m->placed, m->applied});
  EXPECT_EQ(mission.placed_scans().size(), 2u);
}

TEST_F(MissionPipelineTest, OnlyAnchoredScansAreMatchedAgainst) {
  MissionConfig without_graph = config();
  without_graph.graph.reset();  // the graph would match the two scans with each other
  MissionPipeline mission(without_graph);
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  EXPECT_TRUE(mission.anchored(0)) << "the first scan defines the map frame";
  // A scan whose match was refused stays at its reported pose, 2 m off: in the map, but not
  // something later scans are placed against.
  const Pose off = at(-3, -7, 0);
  mission.add(scan_at(at(-5, -9, 0), 2), {off, off});
  EXPECT_FALSE(mission.anchored(1));
  const std::size_t all = mission.points_near(-4, -8, 3).size();
  const std::size_t anchored = mission.points_near(-4, -8, 3, /*anchored_only=*/true).size();
  EXPECT_LT(anchored, all);
  const auto in = mission.match_input(scan_at(at(-5, -9, 0), 3), off);
  ASSERT_TRUE(in);
  EXPECT_EQ(in->map_points.size(),
            mission.points_near(off.x, off.y, in->config.target_radius_m, true).size());

  // Each map point comes with where its scan's scanner stood (the scan's pose, the mount above
  // it), and the new scan's scanner is the mount above its own origin.
  const auto mount = static_cast<float>(without_graph.mapping.sensor_height_m);
  ASSERT_TRUE(in->views.target.fit(in->map_points.size()));
  ASSERT_EQ(in->views.target.origins.size(), 1u) << "only the anchored scan";
  EXPECT_TRUE(in->views.target.of(0).isApprox(Eigen::Vector3f(-15, -8, mount)));
  EXPECT_TRUE(in->views.source.fit(1));
  EXPECT_EQ(in->views.source.of(0), Eigen::Vector3f(0, 0, mount));
  Viewpoints both;
  const PointCloud near = mission.points_near(-4, -8, 30, /*anchored_only=*/false, &both);
  ASSERT_TRUE(both.fit(near.size()));
  ASSERT_EQ(both.origins.size(), 2u);
  EXPECT_TRUE(both.origins[1].isApprox(Eigen::Vector3f(-3, -7, mount)));
  EXPECT_EQ(both.of(near.size() - 1), both.origins[1]) << "the refused scan's points come last";
}

// A place scanned again (a later pass, a second robot): a match near it is made against the
// latest scan there alone, so the match's input stays the size of the site, not of the session.
TEST_F(MissionPipelineTest, APlaceScannedAgainIsMatchedAgainstItsLatestScanOnly) {
  MissionConfig without_graph = config();
  without_graph.graph.reset();
  MissionPipeline mission(without_graph);
  const Pose first = at(-15, -8, 0), again = at(-15.4, -8.3, 40), apart = at(-12, -8, 0);
  mission.add(scan_at(first, 1), {first, first});
  mission.add(scan_at(again, 2), {again, again, /*matched=*/true});
  const auto mount = static_cast<float>(without_graph.mapping.sensor_height_m);
  const auto origins = [&](const Pose& from) {
    const auto in = mission.match_input(scan_at(from, 9), from);
    EXPECT_TRUE(in && in->views.target.fit(in->map_points.size()));
    return in ? in->views.target.origins : std::vector<Eigen::Vector3f>{};
  };
  std::vector<Eigen::Vector3f> seen = origins(at(-5, -9, 0));
  ASSERT_EQ(seen.size(), 1u) << "the first scan's place was scanned again half a metre off";
  EXPECT_TRUE(seen[0].isApprox(Eigen::Vector3f(-15.4F, -8.3F, mount), 1e-3F));
  const auto in = mission.match_input(scan_at(at(-5, -9, 0), 9), at(-5, -9, 0));
  const auto within =
      std::count_if(mission.placed_scans()[1]->points.begin(),
                    mission.placed_scans()[1]->points.end(), [&](const Eigen::Vector3f& p) {
                      return std::hypot(p.x() + 5, p.y() + 9) <= in->config.target_radius_m;
                    });
  EXPECT_EQ(in->map_points.size(), static_cast<std::size_t>(within)) << "the second scan's alone";

  // Three metres on is another place: both are matched against.
  mission.add(scan_at(apart, 3), {apart, apart, /*matched=*/true});
  seen = origins(at(-5, -9, 0));
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_TRUE(seen[1].isApprox(Eigen::Vector3f(-12, -8, mount), 1e-3F));
}

// With the graph, the map's points are gathered for a match as thinly as the match uses them:
// from the graph's thinned copy of each scan, at the graph's pose (issue 19: on a long session
// gathering and thinning millions of points took most of every match).
TEST_F(MissionPipelineTest, WithTheGraphTheMatchReadsEachScanThinned) {
  MissionPipeline mission(config());
  const Pose first = at(-15, -8, 0), second = at(-3, -7, 20);
  mission.add(scan_at(first, 1), {first, first});
  ASSERT_TRUE(add_matched(mission, second, 2));
  const PointCloud scan = scan_at(at(-5, -9, 0), 3);
  const auto in = mission.match_input(scan, at(-5, -9, 0));
  ASSERT_TRUE(in);
  const double r = in->config.target_radius_m;
  const ScanGraph& graph = *mission.graph();
  ASSERT_LE(graph.thinned_voxel_m(0), in->config.registration.voxel_m);
  std::size_t expected = 0;
  for (std::size_t i = 0; i < 2; ++i) {
    const Eigen::Isometry3f to_map = level(mission.poses()[i]).isometry().cast<float>();
    for (const auto& p : graph.thinned(i).points) {
      const Eigen::Vector3f q = to_map * p;
      expected += std::hypot(q.x() + 5, q.y() + 9) <= r ? 1 : 0;
    }
  }
  EXPECT_EQ(in->map_points.size(), expected);
  EXPECT_LT(in->map_points.size(), mission.points_near(-5, -9, r, true).size() / 3);
  ASSERT_TRUE(in->views.target.fit(in->map_points.size()));
  EXPECT_EQ(in->views.target.origins.size(), 2u);
  // The lengths are sized by the scan already: the matcher does not size them again.
  EXPECT_FALSE(in->config.registration.adapt_to_scene);
  // And the match from there lands where the full-resolution one does.
  const MapMatch m = match_to_map(in->map_points, scan, in->prior, in->config, in->views);
  ASSERT_TRUE(m.applied) << m.result.message;
  EXPECT_NEAR(m.placed.x, -5, 0.03);
  EXPECT_NEAR(m.placed.y, -9, 0.03);
}

// With the graph, a scan the map match refused is matched pairwise with the anchored scans
// around it; one pair alone could be a look-alike, two that agree tie it in at its true pose.
TEST_F(MissionPipelineTest, TheGraphPlacesAScanTheMapMatchRefused) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  Placement refused(at(-3, -7, 0), at(-3, -7, 0));  // 2 m off, as a refused match leaves it
  mission.add(scan_at(at(-5, -9, 0), 2), refused);
  EXPECT_FALSE(mission.anchored(1)) << "one pairwise match is not enough";
  EXPECT_FALSE(mission.in_map(1));
  ASSERT_TRUE(mission.last_correction());
  EXPECT_EQ(mission.last_correction()->graph.pairs_matched, 1u);

  // A third scan, placed by the map match, agrees on where the second lies.
  ASSERT_TRUE(add_matched(mission, at(-12, 4, 30), 3));
  EXPECT_TRUE(mission.anchored(1));
  EXPECT_TRUE(mission.in_map(1));
  EXPECT_NEAR(mission.poses()[1].x, -5, 0.03);
  EXPECT_NEAR(mission.poses()[1].y, -9, 0.03);
  ASSERT_TRUE(mission.last_correction());
  EXPECT_EQ(mission.last_correction()->moved, std::vector<std::size_t>{1});
  EXPECT_NEAR(mission.last_correction()->max_moved_m, std::hypot(2.0, 2.0), 0.05);
  // Its points in the map moved with it.
  const PointCloud second = scan_at(at(-5, -9, 0), 2);
  const Eigen::Vector3f moved = mission.poses()[1].isometry().cast<float>() * second.points[0];
  EXPECT_LT((mission.placed_scans()[1]->points[0] - moved).norm(), 1e-3);
  // The second scan joined the map with the third, and the map is what the three make from
  // scratch.
  EXPECT_TRUE(testing_support::same_map(mission.mapping().map(), from_scratch(mission), 1e-4F));
  EXPECT_EQ(mission.mapping().scan_poses().size(), 3u);
}

// The owner (the server's live map) shares each scan's cloud and shows it until the scan moves
// past replace_m / _deg; the pipeline makes no copy for a smaller move, and uses the points where
// the graph has the scan all the same.
TEST_F(MissionPipelineTest, AScanMovedLessThanReplaceKeepsItsCloudButIsUsedWhereTheGraphHasIt) {
  MissionConfig c = config();
  c.replace_m = 10;  // the 2.8 m correction below stays under it
  c.replace_deg = 90;
  MissionPipeline mission(c);
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const Pose refused_at = at(-3, -7, 0);
  const PointCloud second = scan_at(at(-5, -9, 0), 2);
  const auto cloud = mission.add(second, {refused_at, refused_at});
  ASSERT_TRUE(add_matched(mission, at(-12, 4, 30), 3));
  ASSERT_TRUE(mission.in_map(1));
  EXPECT_NEAR(mission.poses()[1].x, -5, 0.03);

  EXPECT_EQ(mission.placed_scans()[1], cloud) << "the same cloud, not a copy";
  EXPECT_NEAR(mission.cloud_poses()[1].x, refused_at.x, 1e-9);
  const Eigen::Vector3f truth = mission.poses()[1].isometry().cast<float>() * second.points[0];
  EXPECT_LT((mission.at_estimate(1).points[0] - truth).norm(), 1e-3);
  // The map's points near it, as a match takes them, lie where the graph has the scan.
  Viewpoints views;
  const PointCloud near = mission.points_near(-5, -9, 1.5, false, &views);
  ASSERT_FALSE(near.empty());
  std::size_t of_second = 0;
  for (std::size_t i = 0; i < near.size(); ++i) {
    const Eigen::Vector3f& origin = views.origins[views.origin_of[i]];
    if ((origin.head<2>() - Eigen::Vector2f(-5, -9)).norm() < 0.05F) ++of_second;
  }
  EXPECT_GT(of_second, 0u) << "the second scan's points and scanner at its estimate";
}

// A scan nothing ties in stays out of the MLS map (no phantom walls for the planner) but is
// kept, and its points go where the graph has it.
TEST_F(MissionPipelineTest, AScanNothingTiesInStaysOutOfTheMap) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const std::size_t cells = mission.mapping().map().occupied_cells();
  PointCloud few;  // too few points to match anything
  for (int i = 0; i < 20; ++i) few.push_back({static_cast<float>(i), 3.0f, 0.0f}, {1, 2, 3});
  mission.add(few, {at(10, 5, 0), at(10, 5, 0)});
  EXPECT_FALSE(mission.anchored(1));
  EXPECT_FALSE(mission.in_map(1));
  EXPECT_EQ(mission.mapping().scan_poses().size(), 1u);
  EXPECT_EQ(mission.mapping().map().occupied_cells(), cells);
  EXPECT_EQ(mission.placed_scans().size(), 2u);
  EXPECT_EQ(mission.poses().size(), 2u);
}

// A lost robot's estimate lies far from where it was sent; the planner is told both, so that it
// does not send the robot to the same candidate again and again.
TEST_F(MissionPipelineTest, AScanOutsideTheMapIsClaimedWhereTheRobotWasSentToo) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  PointCloud few;  // too few points to match anything
  for (int i = 0; i < 20; ++i) few.push_back({static_cast<float>(i), 3.0f, 0.0f}, {1, 2, 3});
  Placement where{at(10, 5, 0), at(10, 5, 0)};
  where.goal = Eigen::Vector3d(-2, 9, 0);
  mission.add(few, where);
  ASSERT_FALSE(mission.in_map(1));
  const std::vector<Eigen::Vector3d> claimed = mission.unplaced_scan_points();
  ASSERT_EQ(claimed.size(), 2u);
  EXPECT_NEAR(claimed[0].x(), 10, 1e-6);
  EXPECT_TRUE(claimed[1].isApprox(Eigen::Vector3d(-2, 9, 0)));
}

// With exact pose sensors (a total station, a simulation without noise) a scan no match places
// joins the map where it is reported: the sensors alone place it within the map's accuracy.
TEST_F(MissionPipelineTest, ExactSensorsPlaceAScanNoMatchPlaced) {
  MissionConfig c = config();
  c.pose_noise = PoseNoise{0, 0, 0, OdometryModel::kAbsolute};
  MissionPipeline mission(c);
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  PointCloud few;  // too few points to match anything
  for (int i = 0; i < 20; ++i) few.push_back({static_cast<float>(i), 3.0f, 0.0f}, {1, 2, 3});
  mission.add(few, {at(10, 5, 0), at(10, 5, 0)});
  EXPECT_TRUE(mission.anchored(1));
  EXPECT_TRUE(mission.in_map(1));
  EXPECT_NEAR(mission.poses()[1].x, 10, 1e-3);
  EXPECT_EQ(mission.graph()->edge_origin(mission.graph()->graph().edges().size() - 1), "sensors");
  // Sensors that err by a metre do not: that scan waits (AScanNothingTiesInStaysOutOfTheMap).
}

// From absolute fixes a match starts metres off with nothing nearer to go by: the planner asks
// a candidate's walls to fix the pose more firmly than with odometry or exact sensors.
TEST_F(MissionPipelineTest, AbsoluteFixesAskForFirmerWallsThanOdometryOrExactSensors) {
  MissionConfig c = config();
  const RegistrabilityConfig& r = c.planner.registrability;
  const double base = r.min_pose_fixing;
  const auto asked = [&] {
    return MissionPipeline(c).planner_config().registrability.min_pose_fixing;
  };
  c.pose_noise = PoseNoise{};  // absolute, σ 1 m, 5°
  EXPECT_DOUBLE_EQ(asked(), base * r.absolute_fix_factor);
  EXPECT_DOUBLE_EQ(MissionPipeline(c).planner().registrability.min_pose_fixing, base);
  c.pose_noise.model = OdometryModel::kDrift;
  EXPECT_DOUBLE_EQ(asked(), base);
  c.pose_noise = PoseNoise{0, 0, 0, OdometryModel::kAbsolute};
  EXPECT_DOUBLE_EQ(asked(), base);
  c.pose_noise = PoseNoise{};
  c.matching.reset();
  EXPECT_DOUBLE_EQ(asked(), base);
}

TEST_F(MissionPipelineTest, WithMatchingOffScansStayWhereTheRobotSays) {
  MissionConfig c = config();
  c.matching.reset();
  MissionPipeline mission(c);
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  EXPECT_FALSE(mission.place(scan_at(at(-5, -9, 0), 2), at(-5, -9, 0)));
}

TEST_F(MissionPipelineTest, PlansTheNextScanInsideTheMovableRegion) {
  MissionPipeline mission(config());
  EXPECT_TRUE(mission.plan_from({-15, -8, 0}, 1).ranked.empty()) << "no map, no plan";
  mission.set_target(world_->target_region());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const Plan plan = mission.plan_from({-15, -8, 0}, 1);
  ASSERT_FALSE(plan.ranked.empty());
  const MappingPipeline& m = mission.mapping();
  for (const Candidate& c : plan.ranked) {
    EXPECT_TRUE(m.target()->contains(c.position.x(), c.position.y()));
    EXPECT_TRUE(m.movable()->contains(m.map().index_of(c.position.x(), c.position.y())));
  }
  // Two robots on one map: one plan each, and not the same best point.
  const auto plans = mission.plan({{"a", {-15, -8, 0}, {}, {}}, {"b", {-20, 5, 0}, {}, {}}});
  ASSERT_EQ(plans.size(), 2u);
  ASSERT_FALSE(plans[0].plan.ranked.empty());
  ASSERT_FALSE(plans[1].plan.ranked.empty());
  EXPECT_GT((plans[0].plan.ranked[0].position - plans[1].plan.ranked[0].position).norm(), 1.0);
}

TEST_F(MissionPipelineTest, TheBestCandidateIsCheckedAgainstWhatAScanThereWouldSee) {
  MissionConfig c = config();
  MissionPipeline mission(c);
  mission.set_target(world_->target_region());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const Plan plan = mission.plan_from({-15, -8, 0}, 1);
  ASSERT_FALSE(plan.ranked.empty());
  ASSERT_TRUE(plan.ranked[0].registrability);
  const auto checked = plan.ranked[0].registrability->predicted_constraint;
  ASSERT_TRUE(checked) << "the best candidate is always checked";
  std::size_t failed = 0;
  for (const Candidate& k : plan.ranked) {
    const auto& v = k.registrability->predicted_constraint;
    if (v && *v < c.view_check.min_constraint) ++failed;
  }
  // Either the best passed, or every candidate checked failed.
  if (*checked < c.view_check.min_constraint) {
    EXPECT_EQ(failed, c.view_check.candidates);
  }
  // The yard's buildings around the first scan fix a scan near it firmly.
  EXPECT_GT(*checked, 0.0);

  c.view_check.enabled = false;
  MissionPipeline unchecked(c);
  unchecked.set_target(world_->target_region());
  unchecked.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  for (const Candidate& k : unchecked.plan_from({-15, -8, 0}, 1).ranked) {
    EXPECT_FALSE(k.registrability->predicted_constraint);
  }
}

TEST_F(MissionPipelineTest, PointsNearKeepsTheMapWithinTheRadius) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const PointCloud near = mission.points_near(-15, -8, 5);
  ASSERT_FALSE(near.empty());
  EXPECT_LT(near.size(), mission.placed_scans()[0]->size());
  for (const auto& p : near.points) {
    EXPECT_LE(std::hypot(p.x() + 15, p.y() + 8), 5.0 + 1e-4);
  }
}

TEST_F(MissionPipelineTest, NewPlannerThresholdsReachTheSegmentation) {
  MissionPipeline mission(config());
  mission.add(scan_at(at(-15, -8, 0), 1), {at(-15, -8, 0), at(-15, -8, 0)});
  const double completed = mission.mapping().regions()->completed_m2();
  PlannerConfig planner = mission.planner();
  planner.regions.completed_radius_m = 5;
  mission.set_planner(planner);
  EXPECT_LT(mission.mapping().regions()->completed_m2(), completed / 4);
  EXPECT_EQ(mission.planner().regions.completed_radius_m, 5);
}

}  // namespace
}  // namespace scanplan

// The scan-to-map hook of paper §4: a scan given in its own frame at a reported pose is placed
// on the map, in a levelled frame that keeps the measured roll and pitch, and corrections the
// pose sensors cannot explain are not applied.
#include <gtest/gtest.h>

#include <cmath>

#include "registration_test_support.hpp"
#include "scanplan/registration/map_matcher.hpp"

namespace scanplan {
namespace {

using test::moved;
using test::pose;
using test::synthetic_yard;

MapMatchConfig quick() {
  MapMatchConfig c;
  c.registration.voxel_m = 0.4;
  c.registration.icp.source_voxel_m = 0.8;
  return c;
}

double metres_between(const Pose& a, const Pose& b) {
  return std::hypot(std::hypot(a.x - b.x, a.y - b.y), a.z - b.z);
}
double degrees_between(double a, double b) {
  return std::abs(rad2deg(std::remainder(a - b, 2 * M_PI)));
}

class MapMatcher : public ::testing::Test {
 protected:
  void SetUp() override {
    map_ = synthetic_yard(1);  // already in the map frame
    truth_ = pose(3.0, -2.0, 0.0, 30, 1.0, -0.5);
    scan_ = moved(synthetic_yard(2), truth_.isometry().inverse());  // in the scan's own frame
  }
  PointCloud map_, scan_;
  Pose truth_;
};

TEST_F(MapMatcher, PlacesAScanReportedOffOnItsTruePose) {
  Pose reported = truth_;
  reported.x += 0.8;
  reported.y -= 0.5;
  reported.z += 0.1;
  reported.yaw += deg2rad(4);
  const MapMatch m = match_to_map(map_, scan_, reported, quick());
  ASSERT_TRUE(m.applied) << m.result.message;
  EXPECT_LT(metres_between(m.placed, truth_), 0.03);
  EXPECT_LT(degrees_between(m.placed.yaw, truth_.yaw), 0.1);
  // Roll and pitch are the inclination sensor's: the 4-DOF match keeps them.
  EXPECT_NEAR(m.placed.roll, reported.roll, 1e-9);
  EXPECT_NEAR(m.placed.pitch, reported.pitch, 1e-9);
}

TEST_F(MapMatcher, PlacesAScanReportedAsFarOffAsThePoseSensorsCanErr) {
  // 3σ of the benchmark's sensors in x-y and yaw at once: beyond a local method's basin.
  Pose reported = truth_;
  reported.x += 4.0;
  reported.y -= 3.0;
  reported.yaw -= deg2rad(20);
  const MapMatch m = match_to_map(map_, scan_, reported, quick());
  ASSERT_TRUE(m.applied) << m.result.message;
  EXPECT_EQ(m.result.method, "search-gicp");
  EXPECT_LT(metres_between(m.placed, truth_), 0.03);
  EXPECT_LT(degrees_between(m.placed.yaw, truth_.yaw), 0.1);
}

TEST_F(MapMatcher, ACorrectionLargerThanTheSensorsCanErrIsNotApplied) {
  Pose reported = truth_;
  reported.x += 0.8;
  MapMatchConfig c = quick();
  c.max_correction_m = 0.3;  // the true correction is 0.8 m
  const MapMatch m = match_to_map(map_, scan_, reported, c);
  EXPECT_FALSE(m.applied);
  EXPECT_FALSE(m.result.converged);
  EXPECT_NE(m.result.message.find("not applied"), std::string::npos) << m.result.message;
  EXPECT_EQ(m.placed.x, reported.x) << "a refused match leaves the reported pose";
}

// Told how far off the pose it starts from may be (the odometry's σ), the match refuses a fit
// outside that prior's 99 % ellipsoid where the fit is no firmer than a look-alike: the odometry
// cannot be that wrong. The same correction within the prior is applied, and so is a fit beyond
// it that holds as much of the scan as no look-alike did (the prior was wrong).
TEST_F(MapMatcher, AFitFarOutsideTheOdometrysPriorIsNotAppliedUnlessFirm) {
  Pose reported = truth_;
  reported.x += 2.0;
  reported.y -= 1.0;
  for (const double sigma_m : {0.4, 1.5}) {
    MapMatchConfig c = quick();
    c.registration.search.prior_sigma_xy_m = sigma_m;
    c.registration.search.prior_sigma_yaw_deg = 2.0;
    const MapMatch m = match_to_map(map_, scan_, reported, c);
    ASSERT_TRUE(m.applied) << m.result.message;
    EXPECT_LT(metres_between(m.placed, truth_), 0.03);
    if (sigma_m > 1) continue;  // 1.5σ
    // 2.2 m is 5.6σ: applied for its firmness alone (most of the yard is on the map).
    EXPECT_GE(m.result.inlier_ratio, c.far_fit_min_inlier_ratio);
    EXPECT_GE(m.result.weakest_constraint, c.far_fit_min_constraint);
    // Asked for more of the scan on the map than it has, or firmer walls, it is a look-alike.
    for (const bool by_inliers : {true, false}) {
      MapMatchConfig strict = c;
      (by_inliers ? strict.far_fit_min_inlier_ratio : strict.far_fit_min_constraint) = 1e3;
      const MapMatch refused = match_to_map(map_, scan_, reported, strict);
      EXPECT_FALSE(refused.applied);
      EXPECT_NE(refused.result.message.find("look-alike"), std::string::npos)
          << refused.result.message;
    }
  }
}

// A refused match leaves x, y and yaw as reported, but the ground still fixes the height: a
// scan left 0.4 m high would put a false step into the map.
TEST_F(MapMatcher, ARefusedMatchIsStillSetOnTheGround) {
  Pose reported = truth_;
  reported.x += 0.8;
  reported.z += 0.4;
  MapMatchConfig c = quick();
  c.max_correction_m = 0.3;
  const MapMatch m = match_to_map(map_, scan_, reported, c);
  ASSERT_FALSE(m.applied);
  EXPECT_TRUE(m.levelled);
  EXPECT_EQ(m.placed.x, reported.x);
  EXPECT_EQ(m.placed.yaw, reported.yaw);
  EXPECT_NEAR(m.placed.z, truth_.z, 0.03);
  // Not without the option, nor beyond what the height sensor can be wrong.
  c.level_refused = false;
  EXPECT_EQ(match_to_map(map_, scan_, reported, c).placed.z, reported.z);
  c.level_refused = true;
  c.max_level_m = 0.2;
  EXPECT_FALSE(match_to_map(map_, scan_, reported, c).levelled);
}

TEST(GroundOffset, IsTheHeightThatPutsTheScansGroundOnTheMaps) {
  const PointCloud map = test::synthetic_yard(1);
  const Pose truth = pose(3.0, -2.0, 0.0, 30, 1.0, -0.5);
  const PointCloud scan = moved(test::synthetic_yard(2), truth.isometry().inverse());
  for (const double dz : {-0.6, 0.0, 0.35}) {
    Pose off = truth;
    off.z += dz;
    off.x -= 1.5;  // x-y wrong by a refused match's metre or two: the ground is flat
    off.y += 1.0;
    const auto found = ground_offset(map, scan, off.isometry());
    ASSERT_TRUE(found) << dz;
    EXPECT_NEAR(*found, -dz, 0.03) << dz;
  }
  // Too little shared ground: no answer.
  Pose away = truth;
  away.x += 200;
  EXPECT_FALSE(ground_offset(map, scan, away.isometry()));
  EXPECT_FALSE(ground_offset(PointCloud{}, scan, truth.isometry()));
}

TEST_F(MapMatcher, MapPointsBeyondTheRadiusAreNotUsed) {
  MapMatchConfig c = quick();
  c.target_radius_m = 1.0;  // a disc with hardly anything in it
  Pose reported = truth_;
  reported.x += 0.8;
  const MapMatch m = match_to_map(map_, scan_, reported, c);
  EXPECT_FALSE(m.applied) << "a floor disc 2 m across cannot place a 30 m scan";
  EXPECT_FALSE(m.result.message.empty());
}

}  // namespace
}  // namespace scanplan

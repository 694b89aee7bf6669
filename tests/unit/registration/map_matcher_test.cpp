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

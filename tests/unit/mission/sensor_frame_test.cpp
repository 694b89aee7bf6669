// The pose sensors' frame in the map frame, from the scans whose map pose a match fixed: a
// reported pose carried into the map frame lands where the scan really is, to within about one
// scan's sensor error, however far from the first scan.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "ground_pose.hpp"
#include "scanplan/mission/sensor_frame.hpp"

namespace scanplan {
namespace {

constexpr auto* at = &testing_support::ground_pose;

// The map frame is the sensor frame turned by 5° and shifted by (3, −2, 0.4): what a first scan
// reported 5° and a few metres off makes of it.
Pose in_map(const Pose& sensor) {
  const double a = deg2rad(5), c = std::cos(a), s = std::sin(a);
  Pose p = sensor;
  p.x = c * sensor.x - s * sensor.y + 3;
  p.y = s * sensor.x + c * sensor.y - 2;
  p.z = sensor.z + 0.4;
  p.yaw = sensor.yaw + a;
  return p;
}

TEST(SensorFrame, WithoutAnchorsAReportedPoseIsTakenAsItIs) {
  const SensorFrame frame;
  const Pose p = frame.to_map(at(10, 20, 30));
  EXPECT_DOUBLE_EQ(p.x, 10);
  EXPECT_DOUBLE_EQ(p.yaw, deg2rad(30));
}

TEST(SensorFrame, OneAnchorCarriesItsOwnPoseExactly) {
  SensorFrame frame;
  const Pose reported = at(10, 20, 30);
  frame.add(reported, in_map(reported));
  const Pose p = frame.to_map(reported);
  const Pose want = in_map(reported);
  EXPECT_NEAR(p.x, want.x, 1e-6);
  EXPECT_NEAR(p.y, want.y, 1e-6);
  EXPECT_NEAR(p.z, want.z, 1e-9);
  EXPECT_NEAR(p.yaw, want.yaw, 1e-4);
}

TEST(SensorFrame, ScansSpreadOverTheSiteFixTheTurnFarBetterThanOneYawReading) {
  // Each anchor's report is wrong by the sensors' σ (1 m, 5°); the map knows the truth.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0, 1);
  SensorFrame frame;
  const double sites[][2] = {{0, 0}, {40, 5}, {80, -10}, {60, 50}, {10, 60}};
  for (const auto& xy : sites) {
    const Pose truth = at(xy[0], xy[1], 0);
    Pose reported = truth;
    reported.x += n(rng);
    reported.y += n(rng);
    reported.yaw += deg2rad(5 * n(rng));
    frame.add(reported, in_map(truth));
  }
  // A scan 150 m out, reported exactly: 5° of frame error would put it 13 m off.
  const Pose far = at(150, 100, 45);
  const Pose got = frame.to_map(far);
  const Pose want = in_map(far);
  EXPECT_LT(std::hypot(got.x - want.x, got.y - want.y), 2.0);
  EXPECT_LT(std::abs(rad2deg(std::remainder(got.yaw - want.yaw, 2 * M_PI))), 1.0);
}

}  // namespace
}  // namespace scanplan

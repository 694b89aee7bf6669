// The pose sensors' frame in the map frame, from the scans whose map pose a match fixed: a
// reported pose carried into the map frame lands where the scan really is, to within about one
// scan's sensor error, however far from the first scan.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
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

// Five scans spread over the site, each reported wrong by the sensors' σ (1 m, 5°), placed at
// the truth by the map.
SensorFrame anchored_over_the_site(std::mt19937_64& rng, const PoseNoise& noise) {
  std::normal_distribution<double> n(0, 1);
  SensorFrame frame(noise);
  const double sites[][2] = {{0, 0}, {40, 5}, {80, -10}, {60, 50}, {10, 60}};
  for (const auto& xy : sites) {
    const Pose truth = at(xy[0], xy[1], 0);
    Pose reported = truth;
    reported.x += n(rng);
    reported.y += n(rng);
    reported.yaw += deg2rad(5 * n(rng));
    frame.add(reported, in_map(truth));
  }
  return frame;
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
  std::mt19937_64 rng(3);
  const SensorFrame frame = anchored_over_the_site(rng, PoseNoise{});
  // A scan 150 m out, reported exactly: 5° of frame error would put it 13 m off.
  const Pose far = at(150, 100, 45);
  const Pose got = frame.to_map(far);
  const Pose want = in_map(far);
  EXPECT_LT(std::hypot(got.x - want.x, got.y - want.y), 2.0);
  EXPECT_LT(std::abs(rad2deg(std::remainder(got.yaw - want.yaw, 2 * M_PI))), 1.0);
}

// How far off a fix carried into the map frame may be: its own error, and the frame's as the
// anchored scans measure it, which grows with the distance from them (the frame's turn).
TEST(SensorFrame, AFixIsAsUnsureAsTheFrameTheAnchorsLeaveIt) {
  const PoseNoise noise;  // σ 1 m, 0.3 m, 5°
  const MoveUncertainty own = SensorFrame(noise).spread(at(100, 0, 0));
  EXPECT_DOUBLE_EQ(own.xy_m, 1.0);
  EXPECT_DOUBLE_EQ(own.yaw_deg, 5.0);

  // One anchor: the frame is as wrong as its one fix, whose heading swings a scan 100 m away.
  SensorFrame one(noise);
  one.add(at(0, 0, 0), at(0, 0, 0));
  const MoveUncertainty far = one.spread(at(100, 0, 0));
  EXPECT_NEAR(far.xy_m, std::sqrt(1 + 1 + std::pow(100 * deg2rad(5), 2)), 0.01);
  EXPECT_NEAR(far.yaw_deg, 5 * std::sqrt(2.0), 0.01);
  EXPECT_NEAR(one.spread(at(0, 0, 0)).xy_m, std::sqrt(2.0), 0.01);

  // Anchors spread over the site: the spread is what the fit's scatter really is. Over many
  // draws of the anchors' sensor errors, the frame's error at a scan 150 m out (reported
  // exactly, so only the frame errs) has the variance the spread predicts beyond the fix's own.
  const Pose target = at(150, 100, 45);
  std::mt19937_64 rng(11);
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  double yaw_scatter = 0, predicted_xy2 = 0, predicted_yaw2 = 0;
  const int draws = 300;
  for (int d = 0; d < draws; ++d) {
    const SensorFrame frame = anchored_over_the_site(rng, noise);
    const Pose got = frame.to_map(target), want = in_map(target);
    const Eigen::Vector2d e(got.x - want.x, got.y - want.y);
    scatter += e * e.transpose() / draws;
    yaw_scatter += std::pow(rad2deg(std::remainder(got.yaw - want.yaw, 2 * M_PI)), 2) / draws;
    const MoveUncertainty u = frame.spread(target);
    predicted_xy2 += (u.xy_m * u.xy_m - 1) / draws;
    predicted_yaw2 += (u.yaw_deg * u.yaw_deg - 25) / draws;
  }
  const double seen_xy2 = Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(scatter).eigenvalues()(1);
  EXPECT_GT(predicted_xy2, 0.7 * seen_xy2);
  EXPECT_LT(predicted_xy2, 1.4 * seen_xy2);
  EXPECT_GT(predicted_yaw2, 0.7 * yaw_scatter);
  EXPECT_LT(predicted_yaw2, 1.4 * yaw_scatter);
  // Far better than one anchor's swing, worse than beside the anchors.
  EXPECT_LT(std::sqrt(predicted_xy2), 3.0);
}

}  // namespace
}  // namespace scanplan

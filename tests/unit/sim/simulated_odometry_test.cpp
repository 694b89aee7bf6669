#include "scanplan/sim/simulated_odometry.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace scanplan {
namespace {

TEST(SimulatedOdometry, ParsesModelNames) {
  EXPECT_EQ(parse_odometry_model("drift"), OdometryModel::kDrift);
  EXPECT_EQ(parse_odometry_model("absolute"), OdometryModel::kAbsolute);
  EXPECT_FALSE(parse_odometry_model("gps"));
  EXPECT_EQ(odometry_model_name(OdometryModel::kDrift), "drift");
}

TEST(SimulatedOdometry, AbsoluteNoiseHasConfiguredSpread) {
  const PoseNoise noise;  // absolute, σ 1 m / 0.3 m / 5°
  const Pose truth;
  SimulatedOdometry odometry(noise, truth, 11);
  double sx = 0, sz = 0, syaw = 0;
  constexpr int kDraws = 20000;
  for (int i = 0; i < kDraws; ++i) {
    odometry.moved(truth, 50.0);  // the distance does not matter to a fix
    const Pose& p = odometry.reported();
    sx += p.x * p.x;
    sz += p.z * p.z;
    syaw += p.yaw * p.yaw;
    ASSERT_EQ(p.roll, 0.0);
    ASSERT_EQ(p.pitch, 0.0);
  }
  EXPECT_NEAR(std::sqrt(sx / kDraws), noise.xy_sigma_m, 0.03);
  EXPECT_NEAR(std::sqrt(sz / kDraws), noise.z_sigma_m, 0.01);
  EXPECT_NEAR(rad2deg(std::sqrt(syaw / kDraws)), noise.yaw_sigma_deg, 0.15);
}

PoseNoise drift() {
  PoseNoise n;
  n.model = OdometryModel::kDrift;
  return n;
}

TEST(SimulatedOdometry, DriftStartsExactAndOneMoveErrsByItsLength) {
  const PoseNoise noise = drift();
  Pose start;
  start.x = 5;
  start.yaw = deg2rad(90);
  start.roll = 0.02;
  Pose there = start;
  there.y += 20;  // 20 m straight ahead
  there.roll = -0.01;
  there.pitch = 0.03;
  double s_along = 0, s_across = 0, s_yaw = 0;
  constexpr int kDraws = 20000;
  for (int i = 0; i < kDraws; ++i) {
    SimulatedOdometry odometry(noise, start, static_cast<std::uint64_t>(i));
    ASSERT_EQ(odometry.reported().x, start.x);
    ASSERT_EQ(odometry.reported().yaw, start.yaw);
    odometry.moved(there, 20.0);
    const Pose& p = odometry.reported();
    s_along += (p.y - there.y) * (p.y - there.y);
    s_across += (p.x - there.x) * (p.x - there.x);
    s_yaw += (p.yaw - there.yaw) * (p.yaw - there.yaw);
    ASSERT_EQ(p.roll, there.roll);
    ASSERT_EQ(p.pitch, there.pitch);
  }
  EXPECT_NEAR(std::sqrt(s_along / kDraws), 0.02 * 20, 0.01);
  EXPECT_NEAR(std::sqrt(s_across / kDraws), 0.02 * 20, 0.01);
  EXPECT_NEAR(rad2deg(std::sqrt(s_yaw / kDraws)), 0.3 * 2, 0.02);
}

// A heading error carries into every later move: after driving out and back along a line the
// robot's error is not the sum of independent position errors but grows with the lever arm.
TEST(SimulatedOdometry, DriftGrowsWithTheDistanceDriven) {
  const PoseNoise noise = drift();
  constexpr int kRuns = 4000;
  double after_2 = 0, after_20 = 0;
  for (int r = 0; r < kRuns; ++r) {
    Pose truth;
    SimulatedOdometry odometry(noise, truth, static_cast<std::uint64_t>(1000 + r));
    for (int k = 1; k <= 20; ++k) {
      truth.x += 10;
      odometry.moved(truth, 10.0);
      const double e2 = std::pow(odometry.reported().x - truth.x, 2) +
                        std::pow(odometry.reported().y - truth.y, 2);
      if (k == 2) after_2 += e2;
      if (k == 20) after_20 += e2;
    }
  }
  const double rms_2 = std::sqrt(after_2 / kRuns), rms_20 = std::sqrt(after_20 / kRuns);
  // Independent errors alone would give √10 ≈ 3.2 times the error after 10 times the moves.
  EXPECT_GT(rms_20 / rms_2, 3.6);
  EXPECT_GT(rms_20, 1.0);  // 200 m at 2 % per move and 0.3° per 10 m: well over a metre
  EXPECT_LT(rms_20, 5.0);
}

}  // namespace
}  // namespace scanplan

// Returns that are not the scene are recognised and dropped without flags: no-returns coded as
// NaN, the scanner's own mount, and the shell of beams that saturated at the sensor's range.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "scanplan/geometry/scan_returns.hpp"

namespace scanplan {
namespace {

// A room-sized scene: points at ranges spread over 1–20 m in every direction.
PointCloud scene(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<float> r(1, 20), u(-1, 1);
  PointCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3f d(u(rng), u(rng), u(rng));
    if (d.norm() < 1e-3f) d = Eigen::Vector3f::UnitX();
    c.push_back(d.normalized() * r(rng), {1, 2, 3});
  }
  return c;
}

void add_shell(PointCloud& c, std::size_t n, float range) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<float> u(-1, 1);
  for (std::size_t i = 0; i < n; ++i) {
    c.push_back(Eigen::Vector3f(u(rng), u(rng), u(rng)).normalized() * range, {9, 9, 9});
  }
}

TEST(ScanReturns, DropsNaNsTheMountAndASaturationShellAndCountsEach) {
  PointCloud c = scene(20000, 1);
  add_shell(c, 400, 32.76f);  // 2 % of the points at one range
  for (int i = 0; i < 30; ++i) c.push_back({0.1f, 0.05f * static_cast<float>(i % 4), 0}, {0, 0, 0});
  c.push_back({std::nanf(""), 0, 0}, {0, 0, 0});
  c.push_back({INFINITY, 1, 0}, {0, 0, 0});
  const DroppedReturns d = drop_bad_returns(c);
  EXPECT_EQ(d.non_finite, 2u);
  EXPECT_EQ(d.mount, 30u);
  EXPECT_EQ(d.saturated, 400u);
  EXPECT_EQ(d.total(), 432u);
  ASSERT_EQ(c.size(), 20000u);
  ASSERT_EQ(c.colors.size(), c.points.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    EXPECT_EQ(c.colors[i], (Rgb{1, 2, 3})) << "colours stay with their points";
    EXPECT_LE(c.points[i].norm(), 20.0f + 1e-3f);
  }
}

TEST(ScanReturns, PointsBeyondAnyScannersReachAreDroppedWithoutHidingTheShell) {
  // One point at 1e30 (a broken driver, a hostile client) would spread the map over the world;
  // nor may it stand in for the farthest range the saturation shell is found at.
  PointCloud c = scene(20000, 3);
  add_shell(c, 400, 32.76f);
  c.push_back({1e30f, 0, 0}, {0, 0, 0});
  c.push_back({0, -3e38f, 1}, {0, 0, 0});
  c.push_back({0, 0, 1500}, {0, 0, 0});
  const DroppedReturns d = drop_bad_returns(c);
  EXPECT_EQ(d.out_of_range, 3u);
  EXPECT_EQ(d.saturated, 400u);
  EXPECT_EQ(d.non_finite, 0u);
  EXPECT_EQ(d.total(), 403u);
  EXPECT_EQ(c.size(), 20000u);
}

TEST(ScanReturns, ARealSceneKeepsItsFarthestPoints) {
  // Ranges that merely end somewhere: the few points near the farthest are the scene.
  PointCloud c = scene(20000, 2);
  const DroppedReturns d = drop_bad_returns(c);
  EXPECT_EQ(d.total(), 0u);
  EXPECT_EQ(c.size(), 20000u);
  // A shell too thin to be one (under 0.5 % of the points): kept.
  PointCloud thin = scene(20000, 3);
  add_shell(thin, 60, 32.76f);
  EXPECT_EQ(drop_bad_returns(thin).saturated, 0u);
}

TEST(ScanReturns, TheShellTellsWhereTheLaserSits) {
  // Recorded about the laser (the origin), not 1 m above it as the robot frame would have it.
  PointCloud c = scene(20000, 4);
  add_shell(c, 400, 32.76f);
  const Eigen::Vector3f robot_frame(0, 0, 1), origin(0, 0, 0);
  EXPECT_EQ(locate_sensor(c, {robot_frame, origin}), origin);
  EXPECT_EQ(locate_sensor(scene(20000, 5), {robot_frame, origin}), robot_frame)
      << "no shell anywhere: the first candidate";
  // Measured from 1 m above the origin the shell is no sphere, and the mount ball lies
  // elsewhere: the nadir ground under a robot-frame scan stays.
  ReturnFilterConfig raised;
  raised.sensor = robot_frame;
  PointCloud ground = scene(20000, 6);
  for (int i = 0; i < 100; ++i) {
    ground.push_back({0.01f * static_cast<float>(i % 10), 0, 0}, {1, 2, 3});
  }
  const auto nadir = [](const PointCloud& cloud) {
    return std::count_if(cloud.points.begin(), cloud.points.end(),
                         [](const Eigen::Vector3f& p) { return p.norm() < 0.2f; });
  };
  drop_bad_returns(ground, raised);
  EXPECT_EQ(nadir(ground), 100);
  drop_bad_returns(ground);
  EXPECT_EQ(nadir(ground), 0);
}

TEST(ScanReturns, AnEmptyOrUncolouredCloudIsFine) {
  PointCloud empty;
  EXPECT_EQ(drop_bad_returns(empty).total(), 0u);
  PointCloud bare;
  bare.points = {{0.1f, 0, 0}, {5, 0, 0}};
  EXPECT_EQ(drop_bad_returns(bare).mount, 1u);
  EXPECT_EQ(bare.size(), 1u);
  EXPECT_FALSE(bare.has_colors());
}

}  // namespace
}  // namespace scanplan

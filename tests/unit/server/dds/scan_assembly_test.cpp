// Gathering a scan's four parts, which arrive on four DDS topics in any order.
#include <gtest/gtest.h>

#include "dds/scan_assembly.hpp"

namespace scanplan::server {
namespace {

using Clock = ScanAssembly::Clock;
using namespace std::chrono_literals;

PointCloud three_points() {
  PointCloud c;
  for (int i = 0; i < 3; ++i) c.points.emplace_back(i, 0, 0);
  return c;
}

PanoramaCamera camera() {
  return PanoramaCamera::for_scanner(ScannerConfig{});
}

TEST(ScanAssembly, AScanIsWholeOnceItsFourPartsAreIn) {
  ScanAssembly a;
  const auto t = Clock::now();
  const ScanAssembly::Key key{"robot1", 42};
  EXPECT_TRUE(a.add_image(key, {1, 2, 3}, t));
  EXPECT_TRUE(a.add_pose(key, Pose{}, t));
  EXPECT_TRUE(a.take(t).complete.empty()) << "no points yet";
  EXPECT_TRUE(a.add_points(key, three_points(), t));
  EXPECT_TRUE(a.take(t).complete.empty()) << "the calibration may still come";
  EXPECT_TRUE(a.add_camera(key, camera(), t));
  const auto taken = a.take(t);
  ASSERT_EQ(taken.complete.size(), 1u);
  const AssembledScan& s = taken.complete[0];
  EXPECT_EQ(s.robot, "robot1");
  EXPECT_EQ(s.stamp_ns, 42);
  EXPECT_EQ(s.points.size(), 3u);
  EXPECT_TRUE(s.jpeg && s.camera);
  EXPECT_EQ(a.open_scans(), 0u);
}

TEST(ScanAssembly, WithoutAPanoramaTheScanWaitsAWhileThenGoesUncoloured) {
  ScanAssembly a;
  const auto t = Clock::now();
  a.add_points({"r", 1}, three_points(), t);
  a.add_pose({"r", 1}, Pose{}, t);
  EXPECT_TRUE(a.take(t + 1s).complete.empty());
  const auto taken = a.take(t + 3s);
  ASSERT_EQ(taken.complete.size(), 1u);
  EXPECT_FALSE(taken.complete[0].jpeg);
}

TEST(ScanAssembly, PartsOfDifferentScansAndRobotsStayApart) {
  ScanAssembly a;
  const auto t = Clock::now();
  a.add_points({"r1", 1}, three_points(), t);
  a.add_pose({"r2", 1}, Pose{}, t);
  a.add_pose({"r1", 2}, Pose{}, t);
  EXPECT_TRUE(a.take(t + 10s).complete.empty());
  EXPECT_EQ(a.open_scans(), 3u);
}

TEST(ScanAssembly, IncompleteScansExpireAndTheOpenOnesAreBounded) {
  ScanAssembly::Config c;
  c.max_open = 2;
  ScanAssembly a(c);
  const auto t = Clock::now();
  for (int k = 0; k < 4; ++k) a.add_pose({"r", k}, Pose{}, t);
  const auto bounded = a.take(t);
  EXPECT_EQ(bounded.dropped.size(), 2u);
  EXPECT_EQ(bounded.dropped[0].key.second, 0) << "the oldest key goes first";
  EXPECT_EQ(a.open_scans(), 2u);
  const auto expired = a.take(t + 61s);
  EXPECT_EQ(expired.dropped.size(), 2u);
  EXPECT_TRUE(expired.dropped[0].had_pose);
  EXPECT_FALSE(expired.dropped[0].had_points);
  EXPECT_EQ(a.open_scans(), 0u);
}

TEST(ScanAssembly, AScanDiscardedWithItsBridgeCannotStartOver) {
  ScanAssembly a;
  const auto t = Clock::now();
  a.add_points({"r1", 7}, three_points(), t);
  a.add_image({"r1", 7}, {1}, t);
  a.add_pose({"r2", 7}, Pose{}, t);
  EXPECT_EQ(a.discard("r1"), 2u);
  EXPECT_FALSE(a.add_pose({"r1", 7}, Pose{}, t)) << "a part still in flight is dropped";
  EXPECT_TRUE(a.add_pose({"r1", 8}, Pose{}, t)) << "the robot's next scan is welcome";
  EXPECT_EQ(a.open_scans(), 2u);
}

}  // namespace
}  // namespace scanplan::server

#include <gtest/gtest.h>

#include <fstream>

#include "scanplan/core/session_store.hpp"

namespace scanplan {
namespace {

class SessionDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("session_store_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

PointCloud cloud_of(int n, float offset) {
  PointCloud c;
  for (int i = 0; i < n; ++i) c.push_back({offset + i, 2.0f * i, 0.5f}, {10, 20, 30});
  return c;
}

TEST_F(SessionDir, ScansSurviveReopeningWithPosesAndPoints) {
  Pose est, placed;
  est.x = 1;
  est.yaw = 0.5;
  placed.x = 1.2;
  placed.yaw = 0.45;
  {
    SessionStore s(dir_);
    EXPECT_EQ(s.add_scan("robot1", est, placed, 42, cloud_of(10, 0)).id, 1);
    EXPECT_EQ(s.add_scan("robot2", est, placed, 43, cloud_of(5, 100)).id, 2);
    s.append_event("approval", R"({"candidate":1,"by":"operator"})");
  }
  SessionStore s(dir_);
  const auto scans = s.scans();
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[1].robot, "robot2");
  EXPECT_EQ(scans[1].points, 5u);
  EXPECT_DOUBLE_EQ(scans[0].placed.x, 1.2);
  EXPECT_DOUBLE_EQ(scans[0].estimated.yaw, 0.5);
  EXPECT_EQ(scans[0].stamp_ns, 42);
  const PointCloud back = s.load_points(scans[1]);
  ASSERT_EQ(back.size(), 5u);
  EXPECT_EQ(back.points[4], Eigen::Vector3f(104, 8, 0.5f));
  EXPECT_EQ(back.colors[0], (Rgb{10, 20, 30}));
  EXPECT_EQ(s.scan(2)->file, "scans/scan_000002.ply");
  EXPECT_FALSE(s.scan(3));
  EXPECT_EQ(s.add_scan("robot1", est, placed, 44, cloud_of(1, 0)).id, 3);
}

TEST_F(SessionDir, EventsReadBackNewestLimitOldestFirst) {
  {
    SessionStore s(dir_);
    EXPECT_TRUE(s.events(10).empty());
    for (int k = 1; k <= 5; ++k) {
      s.append_event(k % 2 ? "approve" : "reject", "{\"candidate\":" + std::to_string(k) + "}");
    }
  }
  SessionStore s(dir_);  // what was recorded survives reopening
  const auto all = s.events(100);
  ASSERT_EQ(all.size(), 5u);
  EXPECT_EQ(all.front().kind, "approve");
  EXPECT_EQ(all.front().json, R"({"candidate":1})");
  EXPECT_EQ(all.back().json, R"({"candidate":5})");
  for (std::size_t k = 1; k < all.size(); ++k) EXPECT_LT(all[k - 1].id, all[k].id);
  EXPECT_EQ(all.front().at.size(), std::string("2026-01-01T00:00:00.000Z").size());
  const auto last = s.events(2);
  ASSERT_EQ(last.size(), 2u);
  EXPECT_EQ(last[0].json, R"({"candidate":4})");
  EXPECT_EQ(last[1].kind, "approve");
}

TEST_F(SessionDir, PartialWritesFromACrashAreDiscardedOnOpen) {
  {
    SessionStore first(dir_);
    first.add_scan("robot1", {}, {}, 1, cloud_of(3, 0));
  }
  // What a process killed mid-scan leaves: a half-written temporary and a PLY whose row never
  // committed.
  std::ofstream(dir_ / "scans" / "scan_000002.ply.part") << "ply\nformat binary";
  std::ofstream(dir_ / "scans" / "scan_000002.ply") << "ply\n";
  SessionStore s(dir_);
  EXPECT_EQ(s.scans().size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "scans" / "scan_000002.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "scans" / "scan_000002.ply.part"));
  EXPECT_EQ(s.add_scan("robot1", {}, {}, 2, cloud_of(2, 0)).id, 2);
}

TEST_F(SessionDir, UnusableDirectoryIsReportedWithItsPath) {
  std::ofstream(dir_.string()) << "a file, not a directory";
  try {
    SessionStore s(dir_);
    FAIL() << "a file in place of the session directory must be refused";
  } catch (const SessionStoreError& e) {
    EXPECT_NE(std::string(e.what()).find(dir_.string()), std::string::npos) << e.what();
  }
  std::filesystem::remove(dir_);
}

}  // namespace
}  // namespace scanplan

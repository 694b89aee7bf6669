#include <gtest/gtest.h>
#include <sqlite3.h>

#include <cmath>
#include <fstream>

#include "storage/session_store.hpp"

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
  for (int i = 0; i < n; ++i) {
    const auto f = static_cast<float>(i);
    c.push_back({offset + f, 2.0f * f, 0.5f}, {10, 20, 30});
  }
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
    EXPECT_EQ(
        s.add_scan("robot2", est, placed, 43, cloud_of(5, 100), Eigen::Vector3d(7, 8, 9), 41.5).id,
        2);
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
  EXPECT_FALSE(scans[0].goal) << "robot1 was not sent anywhere";
  ASSERT_TRUE(scans[1].goal);
  EXPECT_EQ(*scans[1].goal, Eigen::Vector3d(7, 8, 9));
  EXPECT_EQ(scans[1].goal_drive_m, 41.5);
  EXPECT_EQ(scans[0].goal_drive_m, 0);
  const PointCloud back = s.load_points(scans[1]);
  ASSERT_EQ(back.size(), 5u);
  EXPECT_EQ(back.points[4], Eigen::Vector3f(104, 8, 0.5f));
  EXPECT_EQ(back.colors[0], (Rgb{10, 20, 30}));
  EXPECT_EQ(s.scan(2)->file, "scans/scan_000002.ply");
  EXPECT_FALSE(s.scan(3));
  EXPECT_EQ(s.add_scan("robot1", est, placed, 44, cloud_of(1, 0)).id, 3);
}

TEST_F(SessionDir, MatchOutcomesAndPlacementsSurviveReopening) {
  Pose est, corrected, prior;
  est.x = 1;
  corrected.x = 1.4;
  prior.x = 1.1;
  {
    SessionStore s(dir_);
    s.add_scan("robot1", est, est, 1, cloud_of(10, 0));
    s.add_scan("robot1", est, est, 2, cloud_of(10, 0));
    s.add_scan("robot1", est, est, 3, cloud_of(10, 0));
    EXPECT_FALSE(s.scan(1)->match) << "not matched yet";
    s.record_match(2, {true, true, "search-gicp", "", 52.5, 0.31}, corrected);
    s.record_match(3, {false, false, "search-gicp", "only 1% of the source points ...", 40, 0.01},
                   prior);
  }
  SessionStore s(dir_);
  const auto scans = s.scans();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_FALSE(scans[0].match);
  ASSERT_TRUE(scans[1].match);
  EXPECT_TRUE(scans[1].match->applied);
  EXPECT_EQ(scans[1].match->method, "search-gicp");
  EXPECT_DOUBLE_EQ(scans[1].match->time_ms, 52.5);
  EXPECT_DOUBLE_EQ(scans[1].placed.x, 1.4);
  ASSERT_TRUE(scans[2].match);
  EXPECT_FALSE(scans[2].match->applied);
  EXPECT_EQ(scans[2].match->reason, "only 1% of the source points ...");
  EXPECT_DOUBLE_EQ(scans[2].placed.x, 1.1) << "a refused match leaves the prior";
  EXPECT_DOUBLE_EQ(scans[2].estimated.x, 1.0);
  EXPECT_EQ(s.scan(2)->match->inlier_ratio, 0.31);
}

// The pose graph weighs a match by its information when the session is brought back (and
// /api/v1/scans says how firmly it fixed the pose), and every revision of the poses it made is
// kept, the latest per scan read back.
TEST_F(SessionDir, MatchInformationAndPoseRevisionsSurviveReopening) {
  Pose est, first, second;
  first.x = 2.5;
  second.x = 2.53;
  second.yaw = 0.1;
  Eigen::Matrix4d information;
  information << 1e5, 2, 3, 4, 2, 2e5, 0.1, 0.2, 3, 0.1, 3e5, 1.0 / 3, 4, 0.2, 1.0 / 3, 7e4;
  {
    SessionStore s(dir_);
    EXPECT_EQ(s.pose_revision(), 0);
    EXPECT_TRUE(s.latest_poses().empty());
    s.add_scan("robot1", est, est, 1, cloud_of(10, 0));
    s.add_scan("robot1", est, est, 2, cloud_of(10, 0));
    StoredMatch m{true, true, "search-gicp", "", 50, 0.4};
    m.information = information;
    m.weakest_constraint = 0.0731;
    s.record_match(2, m, first);
    EXPECT_EQ(s.record_pose_revision({{2, first, false}}), 1);
    EXPECT_EQ(s.record_pose_revision({{1, est, true}, {2, second, true}}), 2);
  }
  SessionStore s(dir_);
  ASSERT_TRUE(s.scan(2)->match);
  EXPECT_EQ(s.scan(2)->match->information, information) << "to the last bit";
  EXPECT_EQ(s.scan(2)->match->weakest_constraint, 0.0731);
  EXPECT_EQ(s.scan(2)->placed.x, 2.5) << "the match's own placement stays the evidence";
  EXPECT_EQ(s.pose_revision(), 2);
  const auto latest = s.latest_poses();
  ASSERT_EQ(latest.size(), 2u);
  EXPECT_EQ(latest[1].scan, 2);
  EXPECT_DOUBLE_EQ(latest[1].pose.x, 2.53);
  EXPECT_DOUBLE_EQ(latest[1].pose.yaw, 0.1);
  EXPECT_TRUE(latest[1].in_map);
}

// A session recorded before the pose graph and the goals (no information, no goal columns) opens
// with its scans as they were and takes new scans with their goals.
TEST_F(SessionDir, ASessionFromBeforeTheGraphOpensAndGainsTheNewColumns) {
  std::filesystem::create_directories(dir_ / "scans");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir_ / "session.sqlite").c_str(), &db), SQLITE_OK);
  const char* old_schema =
      "CREATE TABLE scans(id INTEGER PRIMARY KEY, robot TEXT NOT NULL, est_x REAL, est_y REAL, "
      "est_z REAL, est_roll REAL, est_pitch REAL, est_yaw REAL, x REAL, y REAL, z REAL, roll REAL, "
      "pitch REAL, yaw REAL, stamp_ns INTEGER, points INTEGER, file TEXT NOT NULL, received_at "
      "TEXT NOT NULL);"
      "CREATE TABLE matches(scan_id INTEGER PRIMARY KEY REFERENCES scans(id), applied INTEGER NOT "
      "NULL, converged INTEGER NOT NULL, method TEXT NOT NULL, reason TEXT NOT NULL, time_ms REAL "
      "NOT NULL, inlier_ratio REAL NOT NULL);"
      "INSERT INTO scans VALUES(1, 'r', 1, 2, 0, 0, 0, 0.5, 1.1, 2.1, 0, 0, 0, 0.49, 7, 10, "
      "'scans/scan_000001.ply', '2026-12-01T00:00:00Z');"
      "INSERT INTO matches VALUES(1, 1, 1, 'search-gicp', '', 40, 0.3);";
  char* error = nullptr;
  ASSERT_EQ(sqlite3_exec(db, old_schema, nullptr, nullptr, &error), SQLITE_OK) << error;
  sqlite3_close(db);
  SessionStore s(dir_);
  const auto old = s.scan(1);
  ASSERT_TRUE(old && old->match);
  EXPECT_DOUBLE_EQ(old->placed.x, 1.1);
  EXPECT_EQ(old->match->information, Eigen::Matrix4d::Zero()) << "not recorded then";
  EXPECT_EQ(old->match->weakest_constraint, 0.0);
  EXPECT_FALSE(old->goal);
  Pose est;
  EXPECT_EQ(s.add_scan("r", est, est, 8, cloud_of(10, 0), Eigen::Vector3d(3, 4, 5)).id, 2);
  EXPECT_EQ(*s.scan(2)->goal, Eigen::Vector3d(3, 4, 5));
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

TEST_F(SessionDir, TheLatestParametersSurviveReopening) {
  {
    SessionStore s(dir_);
    EXPECT_FALSE(s.latest_params());
    s.record_params(R"({"alpha":0.5,"no_go":[]})", "operator");
    s.record_params(R"({"alpha":0.7,"no_go":[[[0,0],[1,0],[1,1]]]})", "operator Ann");
  }
  SessionStore s(dir_);
  EXPECT_EQ(s.latest_params(),
            std::optional<std::string>(R"({"alpha":0.7,"no_go":[[[0,0],[1,0],[1,1]]]})"));
}

TEST_F(SessionDir, PartialWritesFromACrashAreDiscardedAndWholeFilesSetAside) {
  {
    SessionStore first(dir_);
    first.add_scan("robot1", {}, {}, 1, cloud_of(3, 0));
  }
  // What a process killed mid-scan leaves: a half-written temporary and a PLY whose row never
  // committed (twice over: an earlier crash's file is already set aside under the same name).
  std::ofstream(dir_ / "scans" / "scan_000002.ply.part") << "ply\nformat binary";
  std::ofstream(dir_ / "scans" / "scan_000002.ply") << "ply\nsecond\n";
  std::filesystem::create_directories(dir_ / "scans" / "unindexed");
  std::ofstream(dir_ / "scans" / "unindexed" / "scan_000002.ply") << "ply\nfirst\n";
  SessionStore s(dir_);
  EXPECT_EQ(s.scans().size(), 1u);
  EXPECT_FALSE(std::filesystem::exists(dir_ / "scans" / "scan_000002.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "scans" / "scan_000002.ply.part"));
  // Never deleted: a whole file may be someone's only copy.
  EXPECT_TRUE(std::filesystem::exists(dir_ / "scans" / "unindexed" / "scan_000002.ply"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "scans" / "unindexed" / "scan_000002.ply.1"));
  EXPECT_EQ(s.add_scan("robot1", {}, {}, 2, cloud_of(2, 0)).id, 2);
}

TEST_F(SessionDir, ScanFilesWithoutADatabaseAreRefusedAndLeftAlone) {
  {
    SessionStore first(dir_);
    first.add_scan("robot1", {}, {}, 1, cloud_of(3, 0));
    first.add_scan("robot1", {}, {}, 2, cloud_of(3, 0));
  }
  for (const char* f : {"session.sqlite", "session.sqlite-wal", "session.sqlite-shm"}) {
    std::filesystem::remove(dir_ / f);
  }
  try {
    SessionStore s(dir_);
    FAIL() << "opening scan files without their database would start an empty session";
  } catch (const SessionStoreError& e) {
    EXPECT_NE(std::string(e.what()).find("2 scan files"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("session.sqlite"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::filesystem::exists(dir_ / "scans" / "scan_000001.ply"));
  EXPECT_TRUE(std::filesystem::exists(dir_ / "scans" / "scan_000002.ply"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "session.sqlite"));
}

TEST_F(SessionDir, ASecondStoreOnTheSameSessionIsRefusedUntilTheFirstCloses) {
  {
    SessionStore first(dir_);
    first.add_scan("robot1", {}, {}, 1, cloud_of(3, 0));
    try {
      SessionStore second(dir_);
      FAIL() << "two stores on one session would write over each other's scans";
    } catch (const SessionStoreError& e) {
      EXPECT_NE(std::string(e.what()).find("open in another process (pid " +
                                           std::to_string(::getpid()) + ")"),
                std::string::npos)
          << e.what();
    }
    EXPECT_EQ(first.add_scan("robot1", {}, {}, 2, cloud_of(3, 0)).id, 2);
  }
  SessionStore again(dir_);
  EXPECT_EQ(again.scans().size(), 2u);
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

TEST_F(SessionDir, AnnotationsSurviveReopeningAndDeletionsAreKeptOut) {
  std::int64_t victim_ns = 0;
  {
    SessionStore s(dir_);
    const Annotation v =
        s.add_annotation("victim", 1.5, -2.25, 0.5, "two adults, responsive", "operator Ann");
    EXPECT_EQ(v.id, 1);
    EXPECT_GT(v.created_ns, 0);
    EXPECT_EQ(v.created_at.size(), 24u) << v.created_at;  // 2026-11-02T10:11:12.345Z
    victim_ns = v.created_ns;
    EXPECT_EQ(s.add_annotation("hazard", 3, 4, 0, "", "operator").id, 2);
    EXPECT_EQ(s.add_annotation("note", 5, 6, 1, "gas smell", "operator").id, 3);
    EXPECT_TRUE(s.delete_annotation(2, "operator Bob"));
    EXPECT_FALSE(s.delete_annotation(2, "operator Bob")) << "already deleted";
    EXPECT_FALSE(s.delete_annotation(99, "operator")) << "never existed";
  }
  SessionStore s(dir_);
  const auto list = s.annotations();
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].id, 1);
  EXPECT_EQ(list[0].kind, "victim");
  EXPECT_DOUBLE_EQ(list[0].y, -2.25);
  EXPECT_EQ(list[0].text, "two adults, responsive");
  EXPECT_EQ(list[0].author, "operator Ann");
  EXPECT_EQ(list[0].created_ns, victim_ns);
  EXPECT_EQ(list[1].id, 3);
  EXPECT_EQ(s.add_annotation("blocked", 0, 0, 0, "", "operator").id, 4) << "ids are not reused";
}

TEST_F(SessionDir, InvalidAnnotationsAreRefusedAndNothingIsStored) {
  SessionStore s(dir_);
  EXPECT_THROW(s.add_annotation("rubble", 0, 0, 0, "", "operator"), SessionStoreError);
  EXPECT_THROW(s.add_annotation("victim", std::nan(""), 0, 0, "", "operator"), SessionStoreError);
  EXPECT_THROW(s.add_annotation("victim", 0, INFINITY, 0, "", "operator"), SessionStoreError);
  EXPECT_THROW(
      s.add_annotation("note", 0, 0, 0, std::string(kMaxAnnotationTextBytes + 1, 'a'), "operator"),
      SessionStoreError);
  EXPECT_TRUE(s.annotations().empty());
  // Text is stored as given, quotes and all: statements bind values, never splice them.
  const std::string tricky = "'); DROP TABLE annotations; --";
  EXPECT_EQ(s.add_annotation("note", 0, 0, 0, tricky, "operator").text, tricky);
  EXPECT_EQ(s.annotations().at(0).text, tricky);
}

}  // namespace
}  // namespace scanplan

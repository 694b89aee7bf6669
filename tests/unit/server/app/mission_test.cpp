// The mission's transitions without processes: approve → move → arrived → scan; refused; robot
// lost (interrupted, approvable again); cancel; reject; and the conflicts in between. The robots
// are a fake RobotLink that records what it was asked.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "app/mission.hpp"

namespace scanplan::server {
namespace {

class FakeRobots : public RobotLink {
 public:
  struct Move {
    std::string robot;
    double x, y, yaw_deg;
  };
  std::uint32_t request_scan(const std::string& robot) override {
    if (offline) throw NoScannerError("no bridge");
    scans.push_back(robot);
    return next_id++;
  }
  std::uint32_t request_move(const std::string& robot, double x, double y,
                             double yaw_deg) override {
    if (offline) throw NoScannerError("no bridge");
    moves.push_back({robot, x, y, yaw_deg});
    return next_id++;
  }
  void publish_goal(const std::string& robot, const Pose& goal) override {
    goals.emplace_back(robot, goal);
  }
  bool offline = false;
  std::uint32_t next_id = 100;
  std::vector<std::string> scans;
  std::vector<Move> moves;
  std::vector<std::pair<std::string, Pose>> goals;
};

CandidateRecord candidate(std::uint64_t id, int rank, double x, double y) {
  CandidateRecord c;
  c.id = id;
  c.rank = rank;
  c.candidate.position = {x, y, 0.5};
  // Arriving along +y: the robot will face 90°.
  c.candidate.path = {{x, y - 4}, {x, y}};
  return c;
}

class MissionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("mission_test_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(dir_);
    session_ = std::make_unique<SessionStore>(dir_);
    map_ = std::make_unique<LiveMap>(plans_);
    mission_ = std::make_unique<Mission>(*map_, plans_, board_, robots_, *session_, events_);
    PlanRecord a{
        1, 1, "a", "exhaustive", 0.5, 10, {candidate(11, 1, 10, 0), candidate(12, 2, 0, 30)}};
    PlanRecord b{
        2, 1, "b", "exhaustive", 0.5, 10, {candidate(21, 1, 13, 0), candidate(22, 2, 60, 0)}};
    plans_.replace({a, b}, "a");
  }
  void TearDown() override {
    mission_.reset();
    map_.reset();
    session_.reset();
    std::filesystem::remove_all(dir_);
  }
  CandidateState state_of(std::uint64_t id) const { return plans_.find(id)->candidate.state; }
  std::vector<std::string> logged_kinds() const {
    std::vector<std::string> kinds;
    for (const SessionEvent& e : session_->events(100)) kinds.push_back(e.kind);
    return kinds;
  }
  static MissionErrc errc_of(const std::function<void()>& f) {
    try {
      f();
    } catch (const MissionError& e) {
      return e.errc;
    }
    ADD_FAILURE() << "no MissionError";
    return MissionErrc::kNotFound;
  }
  RobotStatus status(std::uint32_t command, RobotActivity activity, std::string message = "") {
    RobotStatus s;
    s.command_id = command;
    s.state = activity;
    s.message = std::move(message);
    return s;
  }

  std::filesystem::path dir_;
  std::unique_ptr<SessionStore> session_;
  PlanBook plans_;
  RobotBoard board_;
  FakeRobots robots_;
  const Events events_;
  std::unique_ptr<LiveMap> map_;
  std::unique_ptr<Mission> mission_;
};

TEST_F(MissionTest, ApprovedArrivedScanned) {
  const Approval a = mission_->approve(11, "operator ann");
  EXPECT_EQ(a.robot, "a");
  EXPECT_EQ(a.command_id, 100u);
  EXPECT_DOUBLE_EQ(a.yaw_deg, 90.0) << "facing along the last leg of the path";
  ASSERT_EQ(robots_.moves.size(), 1u);
  EXPECT_EQ(robots_.moves[0].robot, "a");
  EXPECT_DOUBLE_EQ(robots_.moves[0].x, 10.0);
  ASSERT_EQ(robots_.goals.size(), 1u);
  EXPECT_DOUBLE_EQ(robots_.goals[0].second.z, 0.5);
  EXPECT_EQ(state_of(11), CandidateState::kMoving);
  // A status about another command changes nothing.
  mission_->on_status("a", status(99, RobotActivity::kArrived));
  EXPECT_EQ(state_of(11), CandidateState::kMoving);
  EXPECT_TRUE(robots_.scans.empty());
  mission_->on_status("a", status(100, RobotActivity::kArrived));
  EXPECT_EQ(state_of(11), CandidateState::kReached);
  EXPECT_EQ(robots_.scans, std::vector<std::string>{"a"}) << "arrival brings the scan command";
  EXPECT_EQ(logged_kinds(), (std::vector<std::string>{"approve", "arrived", "scan_requested"}));
}

TEST_F(MissionTest, ARefusedMoveKeepsTheRobotsReason) {
  const Approval a = mission_->approve(11, "operator");
  mission_->on_status("a", status(a.command_id, RobotActivity::kRefused, "a wall in the way"));
  EXPECT_EQ(state_of(11), CandidateState::kRefused);
  EXPECT_EQ(plans_.find(11)->candidate.note, "a wall in the way");
  EXPECT_TRUE(robots_.scans.empty());
  // The robot is free again.
  EXPECT_NO_THROW(mission_->approve(12, "operator"));
}

// A refusal is recorded with where it was and after which scan; a mission made on that session
// (a restarted server) reads it back, and passes over a row without a usable place.
TEST_F(MissionTest, ARefusalIsReadBackAfterARestart) {
  const Approval a = mission_->approve(11, "operator");
  mission_->on_status("a", status(a.command_id, RobotActivity::kRefused, "a wall in the way"));
  session_->append_event("refused", R"({"candidate":12,"robot":"a","x":"east","y":1})");
  session_->append_event("refused", "not json");
  PlanBook restarted;
  const Mission again(*map_, restarted, board_, robots_, *session_, events_);
  ASSERT_EQ(restarted.refused_points("a").size(), 1u);
  EXPECT_EQ(restarted.refused_points("a")[0], Eigen::Vector2d(10, 0));
  EXPECT_TRUE(restarted.refused_points("b").empty());
}

TEST_F(MissionTest, OneMoveAtATimePerRobotAndDecidedCandidatesAreClosed) {
  mission_->approve(11, "operator");
  EXPECT_EQ(errc_of([&] { mission_->approve(11, "operator"); }), MissionErrc::kConflict);
  EXPECT_EQ(errc_of([&] { mission_->approve(12, "operator"); }), MissionErrc::kConflict)
      << "robot a is still driving";
  EXPECT_EQ(errc_of([&] { mission_->reject(11, "operator", ""); }), MissionErrc::kConflict);
  EXPECT_EQ(errc_of([&] { mission_->approve(999, "operator"); }), MissionErrc::kNotFound);
}

TEST_F(MissionTest, TwoRobotsAreNotSentWithinTheClaimSeparation) {
  mission_->approve(11, "operator");  // robot a to (10, 0)
  // Robot b's best is (13, 0): 3 m from a's goal, closer than PlannerConfig::claim_separation_m.
  EXPECT_EQ(errc_of([&] { mission_->approve(21, "operator"); }), MissionErrc::kConflict);
  EXPECT_NO_THROW(mission_->approve(22, "operator"));
}

TEST_F(MissionTest, RejectRecordsTheReasonAndClosesTheCandidate) {
  const Rejection r = mission_->reject(12, "operator bo", "under water");
  EXPECT_EQ(r.reason, "under water");
  EXPECT_EQ(state_of(12), CandidateState::kRejected);
  EXPECT_EQ(errc_of([&] { mission_->approve(12, "operator"); }), MissionErrc::kConflict);
  EXPECT_TRUE(robots_.moves.empty());
}

TEST_F(MissionTest, CancelStopsTheRobotWhereItStands) {
  EXPECT_EQ(errc_of([&] { mission_->cancel(11, "operator"); }), MissionErrc::kConflict)
      << "nothing to cancel before an approval";
  mission_->approve(11, "operator");
  RobotStatus moving = status(100, RobotActivity::kMoving);
  moving.reported.x = 4;
  moving.reported.y = 1;
  board_.set_status("a", moving);
  const Cancellation c = mission_->cancel(11, "operator");
  EXPECT_EQ(c.robot, "a");
  ASSERT_EQ(robots_.moves.size(), 2u);
  EXPECT_DOUBLE_EQ(robots_.moves[1].x, 4.0);
  EXPECT_DOUBLE_EQ(robots_.moves[1].y, 1.0);
  ASSERT_EQ(robots_.goals.size(), 2u);
  EXPECT_DOUBLE_EQ(robots_.goals[1].second.x, 4.0) << "the latched goal is where it stopped";
  EXPECT_EQ(state_of(11), CandidateState::kCancelled);
  // Arrival of the cancelled move changes nothing.
  mission_->on_status("a", status(100, RobotActivity::kArrived));
  EXPECT_EQ(state_of(11), CandidateState::kCancelled);
  EXPECT_TRUE(robots_.scans.empty());
}

TEST_F(MissionTest, ALostRobotInterruptsItsMoveWhichMayBeApprovedAgain) {
  mission_->approve(11, "operator");
  mission_->on_robot_lost({"a", "lease expired", "2026-12-01T00:00:00Z", ScanLoss{7, 0.4f, 2}});
  EXPECT_EQ(state_of(11), CandidateState::kInterrupted);
  EXPECT_NE(plans_.find(11)->candidate.note.find("lease expired"), std::string::npos);
  EXPECT_EQ(logged_kinds(),
            (std::vector<std::string>{"approve", "robot_lost", "scan_failed", "interrupted"}));
  mission_->on_robot_back("a");
  const Approval again = mission_->approve(11, "operator");
  EXPECT_EQ(state_of(11), CandidateState::kMoving);
  EXPECT_EQ(again.command_id, 101u);
}

TEST_F(MissionTest, WithoutARobotNothingChanges) {
  robots_.offline = true;
  EXPECT_EQ(errc_of([&] { mission_->approve(11, "operator"); }), MissionErrc::kNoRobot);
  EXPECT_EQ(state_of(11), CandidateState::kProposed);
  EXPECT_TRUE(logged_kinds().empty());
}

TEST_F(MissionTest, AGoalNeedsAMapAndAKnownRobot) {
  // Plans exist but the map holds no scan: the goal cannot be checked against anything.
  EXPECT_EQ(errc_of([&] { mission_->propose(1, 1, "a", "operator"); }), MissionErrc::kNoMap);
  EXPECT_EQ(errc_of([&] { mission_->propose(1, 1, "nobody", "operator"); }),
            MissionErrc::kUnknownRobot);
  PlanBook empty;
  LiveMap bare(empty);
  Mission fresh(bare, empty, board_, robots_, *session_, events_);
  EXPECT_EQ(errc_of([&] { fresh.propose(1, 1, "", "operator"); }), MissionErrc::kNoMap);
}

}  // namespace
}  // namespace scanplan::server

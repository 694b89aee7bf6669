#include <gtest/gtest.h>

#include "app/states.hpp"

namespace scanplan::server {
namespace {

TEST(States, NamesAreTheApisAndRoundTrip) {
  EXPECT_EQ(to_string(CandidateState::kProposed), "proposed");
  EXPECT_EQ(to_string(CandidateState::kSuperseded), "superseded");
  for (auto a : {RobotActivity::kIdle, RobotActivity::kMoving, RobotActivity::kArrived,
                 RobotActivity::kRefused, RobotActivity::kScanning, RobotActivity::kOffline}) {
    EXPECT_EQ(parse_robot_activity(to_string(a)), a);
  }
  EXPECT_EQ(parse_robot_activity("dancing"), RobotActivity::kUnknown);
  for (auto s : {ScanState::kIdle, ScanState::kRequested, ScanState::kScanning, ScanState::kDone,
                 ScanState::kFailed}) {
    EXPECT_EQ(parse_scan_state(to_string(s)), s);
  }
  EXPECT_FALSE(parse_scan_state("Done"));
}

TEST(States, OnlyProposedAndInterruptedCandidatesAreOpen) {
  EXPECT_TRUE(is_open(CandidateState::kProposed));
  EXPECT_TRUE(is_open(CandidateState::kInterrupted));
  for (auto s :
       {CandidateState::kMoving, CandidateState::kRejected, CandidateState::kRefused,
        CandidateState::kReached, CandidateState::kCancelled, CandidateState::kSuperseded}) {
    EXPECT_FALSE(is_open(s)) << to_string(s);
  }
}

}  // namespace
}  // namespace scanplan::server

#include <gtest/gtest.h>

#include "app/plan_book.hpp"

namespace scanplan::server {
namespace {

CandidateRecord at(std::uint64_t id, int rank, double x) {
  CandidateRecord c;
  c.id = id;
  c.rank = rank;
  c.candidate.position = {x, 0, 0};
  c.candidate.travel_m = 2.5 * x;
  return c;
}

TEST(PlanBook, ANewPlanSupersedesTheUndecidedCandidatesOfTheOld) {
  PlanBook book;
  EXPECT_TRUE(book.empty());
  EXPECT_FALSE(book.plan());
  book.replace({{1, 1, "a", "paper", 0.5, 1, {at(1, 1, 0), at(2, 2, 5)}}}, "a");
  book.set_candidate_state(2, CandidateState::kRejected, "no");
  // The superseded plan is gone from the book; its candidates' states are settled before.
  book.replace({{2, 2, "a", "paper", 0.5, 1, {at(3, 1, 9)}}}, "a");
  EXPECT_EQ(book.plan()->id, 2u);
  EXPECT_FALSE(book.find(1)) << "the old plan was replaced";
  EXPECT_EQ(book.find(3)->robot, "a");
  EXPECT_FALSE(book.set_candidate_state(1, CandidateState::kMoving));
}

TEST(PlanBook, TheLatestRobotsPlanIsTheDefaultAndEachRobotKeepsItsOwn) {
  PlanBook book;
  book.replace({{1, 1, "a", "paper", 0.5, 1, {at(1, 1, 0)}}}, "a");
  book.replace({{2, 2, "b", "paper", 0.5, 1, {at(2, 1, 50)}}}, "b");
  EXPECT_EQ(book.latest_robot(), "b");
  EXPECT_EQ(book.plan()->robot, "b");
  EXPECT_EQ(book.plan("a")->id, 1u);
  EXPECT_EQ(book.plans().size(), 2u);
  EXPECT_TRUE(book.add_candidate("a", at(9, 0, 3)));
  EXPECT_FALSE(book.add_candidate("nobody", at(10, 0, 3)));
  EXPECT_EQ(book.plan("a")->candidates.size(), 2u);
}

TEST(PlanBook, ClaimsAreTheOtherRobotsGoalsElseTheirBestCandidates) {
  PlanBook book;
  book.replace({{1, 1, "a", "paper", 0.5, 1, {at(1, 1, 0), at(2, 2, 5)}},
                {2, 1, "b", "paper", 0.5, 1, {at(3, 1, 50), at(4, 2, 60)}}},
               "b");
  auto claims = book.claims_except("a");
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0].x(), 50) << "b's best";
  book.set_candidate_state(4, CandidateState::kMoving);
  claims = book.claims_except("a");
  ASSERT_EQ(claims.size(), 1u);
  EXPECT_EQ(claims[0].x(), 60) << "b's approved goal";
  const auto driving = book.driving_goals();
  ASSERT_EQ(driving.size(), 1u);
  EXPECT_EQ(driving.at("b").x(), 60);
  EXPECT_TRUE(book.claims_except("b").size() == 1 && book.claims_except("b")[0].x() == 0);
}

// The scan a robot sends after arriving was taken where it was sent (StoredScan::goal), once; a
// move that ended short of its goal leaves nothing to claim.
TEST(PlanBook, ARobotThatReachedItsGoalWasSentThereForItsNextScanOnly) {
  PlanBook book;
  book.replace({{1, 1, "a", "paper", 0.5, 1, {at(1, 1, 10), at(2, 2, 20), at(3, 3, 30)}}}, "a");
  EXPECT_FALSE(book.take_reached_goal("a")) << "not sent anywhere yet";
  book.set_candidate_state(1, CandidateState::kMoving);
  EXPECT_FALSE(book.take_reached_goal("a")) << "still driving";
  book.set_candidate_state(1, CandidateState::kReached);
  book.set_candidate_state(2, CandidateState::kRejected, "not there");
  const auto goal = book.take_reached_goal("a");
  ASSERT_TRUE(goal) << "a rejection of another candidate does not forget the arrival";
  EXPECT_EQ(goal->position.x(), 10);
  EXPECT_EQ(goal->drive_m, 25) << "the path the planner gave it there";
  EXPECT_FALSE(book.take_reached_goal("a")) << "taken by the scan made there";
  EXPECT_FALSE(book.take_reached_goal("b"));
  for (const CandidateState stop :
       {CandidateState::kRefused, CandidateState::kCancelled, CandidateState::kInterrupted}) {
    book.set_candidate_state(1, CandidateState::kReached);
    book.set_candidate_state(3, CandidateState::kMoving);
    book.set_candidate_state(3, stop);
    EXPECT_FALSE(book.take_reached_goal("a")) << to_string(stop) << ": it never got to 30";
  }
}

TEST(PlanBook, ARefusedPointIsKeptForItsRobotUntilAScanNearItChangesTheMap) {
  PlanBook book;
  book.replace({{1, 1, "a", "paper", 0.5, 1, {at(1, 1, 10), at(2, 2, 50)}},
                {2, 1, "b", "paper", 0.5, 1, {at(3, 1, 90)}}},
               "a");
  book.set_candidate_state(1, CandidateState::kMoving);
  book.set_candidate_state(1, CandidateState::kRefused, "the goal lies outside the target region");
  book.set_candidate_state(2, CandidateState::kRejected,
                           "rubble");  // the operator's, not a refusal
  ASSERT_EQ(book.refused_points("a").size(), 1u);
  EXPECT_EQ(book.refused_points("a")[0], Eigen::Vector2d(10, 0));
  EXPECT_TRUE(book.refused_points("b").empty()) << "robot b may still go there";
  // A new plan does not forget it; a scan farther than the radius does not either.
  book.replace({{3, 2, "a", "paper", 0.5, 1, {at(4, 1, 60)}}}, "a");
  book.forget_refusals_near(40, 0, 20, 2);
  EXPECT_EQ(book.refused_points("a").size(), 1u);
  book.forget_refusals_near(25, 0, 20, 3);
  EXPECT_TRUE(book.refused_points("a").empty());
}

// A restarted server reads the refusals back before it reloads the scans: the scans up to the
// one a refusal came after do not forget it, a later scan near it does.
TEST(PlanBook, ARestoredRefusalOutlivesTheScansBeforeIt) {
  PlanBook book;
  book.restore_refusal("a", {{10, 0}, 4});
  book.restore_refusal("a", {{200, 0}, 4});
  for (std::int64_t id = 1; id <= 4; ++id) book.forget_refusals_near(12, 0, 20, id);
  EXPECT_EQ(book.refused_points("a").size(), 2u);
  book.forget_refusals_near(12, 0, 20, 5);
  ASSERT_EQ(book.refused_points("a").size(), 1u);
  EXPECT_EQ(book.refused_points("a")[0], Eigen::Vector2d(200, 0));
  EXPECT_EQ(book.latest_scan(), 5);
}

TEST(PlanBook, IdsAreUniqueAcrossPlans) {
  PlanBook book;
  EXPECT_EQ(book.new_plan_id(), 1u);
  EXPECT_EQ(book.new_plan_id(), 2u);
  EXPECT_EQ(book.new_candidate_id(), 1u);
  EXPECT_EQ(book.new_candidate_id(), 2u);
}

}  // namespace
}  // namespace scanplan::server

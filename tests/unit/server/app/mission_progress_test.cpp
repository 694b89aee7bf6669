#include <gtest/gtest.h>

#include "app/mission_progress.hpp"

namespace scanplan::server {
namespace {

CandidateRecord offering(double unscanned_m2, CandidateState state = CandidateState::kProposed) {
  CandidateRecord c;
  c.candidate.gain_unscanned_m2 = unscanned_m2;
  c.state = state;
  return c;
}

MapAreas completed(double m2) {
  return {m2, 0, 40000 - m2, 0};
}

TEST(MissionProgress, RunningWithAnEstimateFromTheDecliningGains) {
  // Gains of 4000, 2000, 1000 m²: halving each scan; the best point now adds 800 m², the
  // threshold is 0.5 % of 40,000 m² = 200 m²: 800 → 400 → 200 → under it after 2 more halvings.
  const std::vector<MapAreas> after = {completed(5000), completed(9000), completed(11000),
                                       completed(12000)};
  const std::vector<PlanRecord> plans = {{1, 4, "robot1", "paper", 0.5, 1, {offering(800)}}};
  const MissionProgress p = mission_progress(after.back(), after, plans, std::nullopt);
  EXPECT_EQ(p.state, "running");
  EXPECT_NEAR(p.coverage_pct, 30.0, 1e-9);
  EXPECT_DOUBLE_EQ(p.best_gain_m2, 800);
  EXPECT_DOUBLE_EQ(p.threshold_m2, 200);
  ASSERT_TRUE(p.scans_left);
  EXPECT_EQ(*p.scans_left, 2);
  // Gains that do not decline give no estimate.
  const std::vector<MapAreas> steady = {completed(1000), completed(2000), completed(3000)};
  EXPECT_FALSE(mission_progress(steady.back(), steady, plans, std::nullopt).scans_left);
}

TEST(MissionProgress, CompleteWhenNoPointAddsEnoughUnlessAMoveIsUnderWay) {
  const std::vector<MapAreas> after = {completed(30000), completed(30100)};
  std::vector<PlanRecord> plans = {
      {1, 2, "robot1", "paper", 0.5, 1, {offering(150), offering(90)}}};
  const MissionProgress done = mission_progress(after.back(), after, plans, std::nullopt);
  EXPECT_EQ(done.state, "complete");
  EXPECT_EQ(done.scans_left, 0);
  // A robot driving to a point is still a scan to come.
  plans[0].candidates[1].state = CandidateState::kMoving;
  EXPECT_EQ(mission_progress(after.back(), after, plans, std::nullopt).state, "running");
  // The operator's own points and refused ones do not count as suggestions.
  plans[0].candidates = {offering(5000, CandidateState::kRefused), offering(10)};
  plans[0].candidates.push_back(offering(9000));
  plans[0].candidates.back().custom = true;
  EXPECT_EQ(mission_progress(after.back(), after, plans, std::nullopt).state, "complete");
}

// The planner ranks a place the matcher cannot yet place a scan at behind the ones it can
// (Plan::best_gain_m2): while the robot can go on, such a place keeps the mission running.
TEST(MissionProgress, APlaceRankedBehindIsNotDone) {
  const std::vector<MapAreas> after = {completed(28000), completed(29000), completed(29500)};
  std::vector<PlanRecord> plans = {
      {1, 3, "robot1", "paper", 0.5, 1, {offering(150), offering(90)}, 2400}};
  const MissionProgress p = mission_progress(after.back(), after, plans, std::nullopt);
  EXPECT_EQ(p.state, "running");
  EXPECT_DOUBLE_EQ(p.best_gain_m2, 150);
  EXPECT_DOUBLE_EQ(p.best_left_m2, 2400);
  // Gains halving each scan: 2400 → 1200 → 600 → 300 → 150 (under 200) in four more.
  ASSERT_TRUE(p.scans_left);
  EXPECT_EQ(*p.scans_left, 4);
  // Every suggestion refused: the plan leads nowhere, whatever it ranked behind.
  for (CandidateRecord& c : plans[0].candidates) c.state = CandidateState::kRefused;
  EXPECT_EQ(mission_progress(after.back(), after, plans, std::nullopt).state, "complete");
}

TEST(MissionProgress, TheOperatorsFinishStands) {
  const std::vector<MapAreas> after = {completed(1000)};
  const MissionProgress p = mission_progress(
      after.back(), after, {},
      std::make_pair(std::string("operator Ann"), std::string("2026-12-03T10:00:00Z")));
  EXPECT_EQ(p.state, "finished");
  EXPECT_EQ(p.finished_by, "operator Ann");
  EXPECT_EQ(mission_progress({}, {}, {}, std::nullopt).state, "running") << "before any scan";
}

}  // namespace
}  // namespace scanplan::server

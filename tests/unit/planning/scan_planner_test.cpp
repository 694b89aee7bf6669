#include "scanplan/planning/scan_planner.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scanplan/planning/fleet_planner.hpp"
#include "scanplan/planning/scan_claims.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

constexpr PlannerPolicy kAllPolicies[] = {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive,
                                          PlannerPolicy::kTravel, PlannerPolicy::kNearestFrontier,
                                          PlannerPolicy::kRandom};

// A 90 m × 40 m yard scanned once from (40, 20). A 3 m wall at x = 50 from y = -5 to 34 hides
// the east half; the way round it is its north end. Ground farther than 20 m from the scan
// point in the west is low-resolution (M), the hidden east unscanned (U): paper Fig. 5's
// situation, where α = 1 should look behind the wall and α = 0 should go west.
class WallYard : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    world_ = new World(parse_world(R"({"name": "wall_yard",
      "bounds": {"min": [0, 0], "max": [90, 40]}, "ground": {"z": 0.0},
      "objects": [{"type": "box", "min": [50, -5, 0], "max": [50.3, 34, 3.0]}],
      "start": [40, 20, 0]})",
                                   "wall_yard"));
    const RayCaster caster(*world_);
    map_ = new MlsMap();
    map_->insert_scan(simulate_scan(caster, world_->scanner, world_->start, 1),
                      world_->start.isometry(), {0, 0, world_->scanner.mount_height_m});
    target_ = new TargetRegion(world_->target_region());
  }
  static void TearDownTestSuite() {
    delete target_;
    delete map_;
    delete world_;
  }

  PlanInput input() const { return {*map_, *target_, scan_points_, {40, 20, 0}}; }
  static Plan plan(PlannerPolicy policy, double alpha, std::uint64_t seed = 1) {
    PlannerConfig cfg;
    cfg.policy = policy;
    cfg.alpha = alpha;
    cfg.seed = seed;
    return plan_next_scan({*map_, *target_, scan_points_, {40, 20, 0}}, cfg);
  }

  static World* world_;
  static MlsMap* map_;
  static TargetRegion* target_;
  static const std::vector<Eigen::Vector2d> scan_points_;
};
World* WallYard::world_ = nullptr;
MlsMap* WallYard::map_ = nullptr;
TargetRegion* WallYard::target_ = nullptr;
const std::vector<Eigen::Vector2d> WallYard::scan_points_ = {{40, 20}};

// Within a few metres of the wall's north end, on the side where the hidden half opens up.
bool past_the_wall(const Candidate& c) {
  return c.position.x() > 46 && c.position.x() < 60 && c.position.y() > 32;
}

TEST_F(WallYard, EveryPolicyFindsThePointPastTheWall) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive,
                                PlannerPolicy::kTravel, PlannerPolicy::kNearestFrontier}) {
    const Plan plan = WallYard::plan(p, 0.5);
    ASSERT_FALSE(plan.ranked.empty()) << policy_name(p);
    const Candidate& best = plan.ranked.front();
    EXPECT_TRUE(past_the_wall(best)) << policy_name(p) << " chose " << best.position.transpose();
    EXPECT_GT(best.gain_unscanned_m2, 500) << policy_name(p);
  }
  // Random only has to choose somewhere a scan gains something.
  const Plan random = plan(PlannerPolicy::kRandom, 0.5);
  ASSERT_FALSE(random.ranked.empty());
  for (const Candidate& c : random.ranked) EXPECT_GE(c.f, 1.0);
}

TEST_F(WallYard, HillClimbingReachesTheExhaustiveOptimum) {
  PlannerConfig exact;
  exact.policy = PlannerPolicy::kExhaustive;
  exact.completion_weight = 0;  // F alone: its optimum
  const double best = plan_next_scan(input(), exact).ranked.front().f;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const Plan paper = plan(PlannerPolicy::kPaper, 0.5, seed);
    EXPECT_GE(paper.ranked.front().f, 0.98 * best) << "seed " << seed;
    EXPECT_LE(paper.ranked.front().f, best);
  }
}

// Exhaustive ranks by F + w · area((U∪M)∩C_B): of two points with nearly the same F the one
// completing more goes first, and never one whose F is more than w · (a scan's whole completed
// disc) below the optimum.
TEST_F(WallYard, ExhaustiveBreaksNearTiesInFByCompletion) {
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  cfg.completion_weight = 0;
  const Candidate exact = plan_next_scan(input(), cfg).ranked.front();
  cfg.completion_weight = 0.05;
  const Candidate top = plan_next_scan(input(), cfg).ranked.front();
  EXPECT_LE(top.f, exact.f);
  EXPECT_GE(top.f, exact.f - cfg.completion_weight * M_PI * std::pow(20.0 + 1.5, 2));
  EXPECT_GE(top.gain_completed_m2, exact.gain_completed_m2);
  EXPECT_DOUBLE_EQ(top.score, top.f + cfg.completion_weight * top.gain_completed_m2);
  EXPECT_GE(top.score, exact.f + cfg.completion_weight * exact.gain_completed_m2);
  // What is completed is at most what is seen within 20 m: U and M cells in C_B.
  EXPECT_LE(top.gain_low_res_m2, top.gain_completed_m2);
  EXPECT_LE(top.gain_completed_m2, top.gain_low_res_m2 + top.gain_unscanned_m2);
  // Seen from B, the map so far: what matching the scan there will go on.
  EXPECT_GT(top.overlap_m2, 100.0);
  cfg.completion_weight = -1;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
}

// Paper §3.4, Fig. 5/6: with α = 1 the next scan goes where the unknown is, with α = 0 where
// the low-resolution region can be brought within 20 m.
TEST_F(WallYard, AlphaOneExploresAlphaZeroRefinesTheLowResolutionRegion) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive}) {
    const Candidate explore = plan(p, 1.0).ranked.front();
    const Candidate refine = plan(p, 0.0).ranked.front();
    EXPECT_TRUE(past_the_wall(explore)) << explore.position.transpose();
    EXPECT_LT(refine.position.x(), 30) << "west, among the far cells of the first scan";
    EXPECT_GT((explore.position - refine.position).head<2>().norm(), 20);
    EXPECT_GT(explore.gain_unscanned_m2, 2 * refine.gain_unscanned_m2);
    EXPECT_GT(refine.gain_low_res_m2, 5 * explore.gain_low_res_m2);
    EXPECT_DOUBLE_EQ(explore.f, explore.gain_unscanned_m2);
    EXPECT_DOUBLE_EQ(refine.f, refine.gain_low_res_m2);
  }
}

TEST_F(WallYard, NoCandidateIsOffTheMovableRegion) {
  for (const PlannerPolicy p : kAllPolicies) {
    for (const double alpha : {0.0, 0.5, 1.0}) {
      const Plan plan = WallYard::plan(p, alpha);
      ASSERT_FALSE(plan.ranked.empty()) << policy_name(p) << " α " << alpha;
      for (const Candidate& c : plan.ranked) {
        const CellIndex cell = map_->index_of(c.position.x(), c.position.y());
        EXPECT_TRUE(plan.movable.contains(cell)) << policy_name(p) << " " << c.position.transpose();
        EXPECT_TRUE(target_->contains(c.position.x(), c.position.y()));
        // The path: from the robot's cell to B, cell by cell over the movable region, as long
        // as it says.
        ASSERT_GE(c.path.size(), 1u);
        EXPECT_LE((c.path.front() - Eigen::Vector2d(40.5, 20.5)).norm(), 1.5);
        EXPECT_LE((c.path.back() - c.position.head<2>()).norm(), 1e-9);
        double length = 0;
        for (std::size_t k = 0; k < c.path.size(); ++k) {
          EXPECT_TRUE(plan.movable.contains(map_->index_of(c.path[k].x(), c.path[k].y())));
          if (k == 0) continue;
          const double step = (c.path[k] - c.path[k - 1]).norm();
          EXPECT_LE(step, std::sqrt(2.0) + 1e-9);
          length += step;
        }
        EXPECT_NEAR(length, c.travel_m, 1e-3);
      }
    }
  }
}

TEST_F(WallYard, TheSameSeedGivesTheSamePlanOnAnyThreadCount) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kRandom}) {
    PlannerConfig cfg;
    cfg.policy = p;
    cfg.seed = 7;
    cfg.threads = 1;
    const Plan one = plan_next_scan(input(), cfg);
    cfg.threads = 2;
    const Plan two = plan_next_scan(input(), cfg);
    ASSERT_EQ(one.ranked.size(), two.ranked.size());
    EXPECT_EQ(one.evaluations, two.evaluations);
    for (std::size_t k = 0; k < one.ranked.size(); ++k) {
      EXPECT_EQ(one.ranked[k].position, two.ranked[k].position) << policy_name(p);
      EXPECT_EQ(one.ranked[k].f, two.ranked[k].f);
    }
  }
  // Another seed draws other random cells.
  EXPECT_NE(plan(PlannerPolicy::kRandom, 0.5, 1).ranked.front().position,
            plan(PlannerPolicy::kRandom, 0.5, 2).ranked.front().position);
}

TEST_F(WallYard, RankedCandidatesAreDistinctPlacesBestFirst) {
  const Plan plan = WallYard::plan(PlannerPolicy::kExhaustive, 0.5);
  ASSERT_EQ(plan.ranked.size(), 5u);
  for (std::size_t k = 1; k < plan.ranked.size(); ++k) {
    EXPECT_LE(plan.ranked[k].score, plan.ranked[k - 1].score);
    for (std::size_t j = 0; j < k; ++j) {
      EXPECT_GE((plan.ranked[k].position - plan.ranked[j].position).head<2>().norm(), 5.0);
    }
  }
  std::size_t in_target = 0;
  for (std::size_t o = 0; o < plan.movable.patch.values.size(); ++o) {
    const Eigen::Vector2d c = map_->center_of(plan.movable.patch.index_at(o));
    in_target += plan.movable.patch.values[o] >= 0 && target_->contains(c.x(), c.y());
  }
  EXPECT_EQ(plan.evaluations, in_target) << "every movable cell in the target, once";
}

TEST_F(WallYard, TravelTradesGainForDistance) {
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kTravel;
  cfg.travel_cost_per_m = 0;
  const Candidate free_travel = plan_next_scan(input(), cfg).ranked.front();
  const Candidate best = plan(PlannerPolicy::kExhaustive, 0.5).ranked.front();
  EXPECT_GE(free_travel.f, 0.98 * best.f) << "with driving free, travel climbs F as paper does";
  EXPECT_DOUBLE_EQ(free_travel.score, free_travel.f);
  cfg.travel_cost_per_m = 0.1;  // 10 m of driving cost the best scan's whole gain
  cfg.travel_free_m = 0;
  const Candidate near = plan_next_scan(input(), cfg).ranked.front();
  EXPECT_LT(near.travel_m, 5.0);
  EXPECT_LE(near.score, near.f);
  EXPECT_GT(near.f, 0);
  // Within the free radius only F counts: the far best point again.
  cfg.travel_free_m = best.travel_m + 1;
  const Candidate within = plan_next_scan(input(), cfg).ranked.front();
  EXPECT_GE(within.f, 0.98 * best.f);
  EXPECT_DOUBLE_EQ(within.score, within.f);
}

TEST_F(WallYard, EvaluateAgreesWithThePlan) {
  const Candidate best = plan(PlannerPolicy::kExhaustive, 0.5).ranked.front();
  PlannerConfig cfg;
  Candidate detail;
  EXPECT_DOUBLE_EQ(evaluate(input(), cfg, best.position, &detail), best.f);
  EXPECT_DOUBLE_EQ(detail.gain_unscanned_m2, best.gain_unscanned_m2);
  EXPECT_DOUBLE_EQ(detail.gain_low_res_m2, best.gain_low_res_m2);
  EXPECT_DOUBLE_EQ(best.f, 0.5 * best.gain_unscanned_m2 + 0.5 * best.gain_low_res_m2);
}

// The screening's sparser fan only chooses where the climbs start: every candidate of a paper
// or travel plan carries the full fan's F, and the climbs still reach the optimum.
TEST_F(WallYard, TheSparseScreeningOnlyChoosesWhereToClimb) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kTravel}) {
    PlannerConfig cfg;
    cfg.policy = p;
    cfg.screening_coarsening = 4;
    const Plan plan = plan_next_scan(input(), cfg);
    ASSERT_FALSE(plan.ranked.empty()) << policy_name(p);
    for (const Candidate& c : plan.ranked) {
      Candidate full;
      EXPECT_DOUBLE_EQ(evaluate(input(), cfg, c.position, &full), c.f) << policy_name(p);
      EXPECT_DOUBLE_EQ(full.gain_unscanned_m2, c.gain_unscanned_m2) << policy_name(p);
    }
    EXPECT_TRUE(past_the_wall(plan.ranked.front())) << policy_name(p);
    // The screening's own looks are counted, and a plan through the full fan looks as often.
    cfg.screening_coarsening = 1;
    const Plan same_fan = plan_next_scan(input(), cfg);
    EXPECT_GT(plan.evaluations, 500u) << policy_name(p);
    EXPECT_NEAR(static_cast<double>(plan.evaluations), static_cast<double>(same_fan.evaluations),
                0.2 * static_cast<double>(same_fan.evaluations))
        << policy_name(p);
  }
}

TEST_F(WallYard, NothingLeftToScanGivesAnEmptyPlan) {
  // A target 10 m around the scan point: all of it scan-completed.
  const TargetRegion small = TargetRegion::rectangle({35, 15}, {45, 25});
  PlannerConfig cfg;
  for (const PlannerPolicy p : kAllPolicies) {
    cfg.policy = p;
    const Plan plan = plan_next_scan({*map_, small, scan_points_, {40, 20, 0}}, cfg);
    EXPECT_TRUE(plan.ranked.empty()) << policy_name(p);
    EXPECT_EQ(plan.regions.unscanned + plan.regions.low_resolution, 0u);
  }
  // A robot nowhere near the map has no movable region.
  const Plan lost = plan_next_scan({*map_, *target_, scan_points_, {500, 500, 0}}, cfg);
  EXPECT_TRUE(lost.ranked.empty());
  EXPECT_EQ(lost.movable.cells, 0u);
}

TEST_F(WallYard, ConfigOutOfRangeIsRefused) {
  PlannerConfig cfg;
  cfg.alpha = 1.5;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
  cfg = {};
  cfg.hill_climb_starts = 0;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
  cfg = {};
  cfg.screening_coarsening = 0;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
  cfg = {};
  cfg.lattice_m = 0;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
  cfg = {};
  EXPECT_THROW(plan_next_scan({*map_, *target_, scan_points_, {std::nan(""), 0, 0}}, cfg),
               std::invalid_argument);
}

// With an anchored map (the scans the matcher trusts) every candidate carries the forecast of
// its match, and F is scaled down where a scan would have nothing trusted to match against.
TEST_F(WallYard, CandidatesCarryTheMatchForecastAndTheUnregistrableLoseTheirScore) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive}) {
    PlannerConfig cfg;
    cfg.policy = p;
    PlanInput in = input();
    in.anchored = map_;  // the one scan is the anchored map
    const Plan trusted = plan_next_scan(in, cfg);
    ASSERT_FALSE(trusted.ranked.empty());
    // One scan from west of the wall: a scan anywhere sees some of what it saw, and from past
    // the wall the ground it opens up is not on the map (0.14–0.3 of the scan's points are
    // forecast on it).
    for (const Candidate& c : trusted.ranked) {
      ASSERT_TRUE(c.registrability) << policy_name(p);
      const Registrability& r = *c.registrability;
      EXPECT_GT(r.overlap_share, 0.1) << c.position.transpose();
      EXPECT_GE(r.pose_fixing, 0) << c.position.transpose();
      const RegistrabilityConfig& rc = cfg.registrability;
      const double s =
          std::min(r.overlap_share / rc.min_overlap_share, r.pose_fixing / rc.min_pose_fixing);
      EXPECT_DOUBLE_EQ(r.factor, s >= 1 ? 1.0 : std::max(rc.floor_share, s * s));
      if (p == PlannerPolicy::kPaper) {
        EXPECT_NEAR(c.score, c.f * r.factor, 1e-9 * c.f);
      }
    }
    // Past the wall a scan meets its east face, which the map does not hold: the west face
    // fixes a scan in front of it only.
    PlannerConfig any_side = cfg;
    any_side.registrability.sided_walls = false;
    for (const double x : {45.0, 60.0}) {
      Candidate sided, unsided;
      evaluate(in, cfg, {x, 20, 0}, &sided);
      evaluate(in, any_side, {x, 20, 0}, &unsided);
      ASSERT_TRUE(sided.registrability && unsided.registrability);
      if (x < 50) {
        EXPECT_EQ(sided.registrability->pose_fixing, unsided.registrability->pose_fixing);
      } else {
        EXPECT_LT(sided.registrability->pose_fixing, 0.5 * unsided.registrability->pose_fixing);
      }
    }
    EXPECT_FALSE(plan_next_scan(input(), cfg).ranked.front().registrability)
        << "no anchored map, no forecast";
    // Nothing anchored: every candidate keeps the least share of its F.
    const MlsMap nothing;
    in.anchored = &nothing;
    const Plan untrusted = plan_next_scan(in, cfg);
    ASSERT_FALSE(untrusted.ranked.empty());
    for (const Candidate& c : untrusted.ranked) {
      ASSERT_TRUE(c.registrability);
      EXPECT_EQ(c.registrability->overlap_share, 0.0);
      EXPECT_EQ(c.registrability->factor, cfg.registrability.floor_share);
      if (p == PlannerPolicy::kPaper) {
        EXPECT_NEAR(c.score, c.f * cfg.registrability.floor_share, 1e-9 * c.f);
      }
    }
    // Switched off, the plan is the paper's own.
    cfg.registrability.enabled = false;
    const Plan off = plan_next_scan(in, cfg);
    const Plan alone = plan_next_scan(input(), cfg);
    ASSERT_EQ(off.ranked.size(), alone.ranked.size());
    for (std::size_t k = 0; k < off.ranked.size(); ++k) {
      EXPECT_EQ(off.ranked[k].position, alone.ranked[k].position) << policy_name(p);
    }
  }
}

// With drifting odometry, a candidate a long drive away keeps the share reach² of its
// forecast (drive_reach); one the matcher's search reaches keeps its forecast as it was.
TEST_F(WallYard, ALongDriveOnDriftingOdometryLowersTheScore) {
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  PlanInput in = input();
  in.anchored = map_;
  const Plan steady = plan_next_scan(in, cfg);
  // Drift so strong that the search reaches 3σ of the pose for 20 m of driving.
  DriveDrift drift;
  drift.xy_per_m = 0.1;
  in.drift = &drift;
  const Plan drifting = plan_next_scan(in, cfg);
  ASSERT_FALSE(steady.ranked.empty());
  int beyond = 0, compared = 0;
  for (const Candidate& c : drifting.ranked) {
    ASSERT_TRUE(c.registrability);
    const Registrability& r = *c.registrability;
    EXPECT_NEAR(r.reach, drive_reach(drift, c.travel_m, cfg.registrability), 1e-12);
    EXPECT_EQ(r.reach == 1.0, c.travel_m <= 20.0) << c.travel_m;
    beyond += r.reach < 1;
    for (const Candidate& s : steady.ranked) {
      if (s.position != c.position) continue;
      ++compared;
      EXPECT_EQ(s.registrability->reach, 1.0);
      EXPECT_NEAR(r.factor,
                  std::max(cfg.registrability.floor_share,
                           s.registrability->factor * (r.reach < 1 ? r.reach * r.reach : 1.0)),
                  1e-12);
    }
  }
  EXPECT_GT(beyond, 0);
  EXPECT_GT(compared, 0);
}

// Two robots on one map: robot A is going past the wall's end; robot B, planned next with A's
// goal claimed, is sent elsewhere, and what A will see no longer counts for B.
TEST_F(WallYard, AClaimedScanPointSendsTheNextRobotElsewhere) {
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive,
                                PlannerPolicy::kTravel, PlannerPolicy::kNearestFrontier}) {
    const Candidate a = plan(p, 0.5).ranked.front();
    ASSERT_TRUE(past_the_wall(a)) << policy_name(p);
    const std::vector<Eigen::Vector3d> claimed = {a.position};
    PlannerConfig cfg;
    cfg.policy = p;
    PlanInput in = input();
    in.claimed = &claimed;
    const Plan b = plan_next_scan(in, cfg);
    ASSERT_FALSE(b.ranked.empty()) << policy_name(p);
    for (const Candidate& c : b.ranked) {
      EXPECT_GE((c.position - a.position).head<2>().norm(), cfg.claim_separation_m)
          << policy_name(p) << " " << c.position.transpose();
    }
    // The map's own segmentation is returned, not the claimed one.
    const Plan alone = plan(p, 0.5);
    EXPECT_EQ(b.regions.unscanned, alone.regions.unscanned);
    EXPECT_EQ(b.regions.completed, alone.regions.completed);
  }
  // F with A's claim is what is left after A's scan: B's best is no longer behind the wall,
  // where A will look, and F there is at most what it is alone.
  const Candidate a = plan(PlannerPolicy::kExhaustive, 0.5).ranked.front();
  const std::vector<Eigen::Vector3d> claimed = {a.position};
  PlanInput in = input();
  in.claimed = &claimed;
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  const Candidate b = plan_next_scan(in, cfg).ranked.front();
  EXPECT_FALSE(past_the_wall(b)) << b.position.transpose();
  EXPECT_LE(b.f, evaluate(input(), cfg, b.position));
  EXPECT_DOUBLE_EQ(evaluate(in, cfg, b.position), b.f);
  // A second scan at A's own point gains next to nothing once A's is claimed.
  EXPECT_LT(evaluate(in, cfg, a.position), 0.05 * a.f);
}

// Two robots on one map: the spot past the wall goes to the robot nearer it, whichever is listed
// first, and the other is sent at least claim_separation_m away.
TEST_F(WallYard, TheFleetGivesTheBestSpotToTheNearerRobot) {
  const FleetRobot far{"far", {40, 20, 0}, {}, {}}, near{"near", {47, 30, 0}, {}, {}};
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  const double alone = plan(PlannerPolicy::kExhaustive, 0.5).ranked.front().f;
  for (const auto& robots :
       {std::vector<FleetRobot>{far, near}, std::vector<FleetRobot>{near, far}}) {
    const std::vector<FleetPlan> plans = plan_fleet(*map_, *target_, scan_points_, robots, {}, cfg);
    ASSERT_EQ(plans.size(), 2u);
    EXPECT_EQ(plans[0].robot, "near");
    EXPECT_EQ(plans[1].robot, "far");
    ASSERT_FALSE(plans[0].plan.ranked.empty());
    ASSERT_FALSE(plans[1].plan.ranked.empty());
    const Candidate& first = plans[0].plan.ranked.front();
    EXPECT_TRUE(past_the_wall(first)) << first.position.transpose();
    EXPECT_GE(first.f, 0.98 * alone);
    for (const Candidate& c : plans[1].plan.ranked) {
      EXPECT_GE((c.position - first.position).head<2>().norm(), cfg.claim_separation_m);
    }
  }
  // One robot: the single-robot plan.
  const auto one = plan_fleet(*map_, *target_, scan_points_, {far}, {}, cfg);
  ASSERT_EQ(one.size(), 1u);
  EXPECT_DOUBLE_EQ(one[0].plan.ranked.front().f, alone);
  cfg.fleet_tie_share = 1.5;
  EXPECT_THROW(plan_fleet(*map_, *target_, scan_points_, {far}, {}, cfg), std::invalid_argument);
}

TEST_F(WallYard, ClaimingAScanMarksWhatItWouldSeeAsSegmentationWould) {
  PlannerConfig cfg;
  RegionMap regions = segment_regions(*map_, *target_, scan_points_, cfg.regions);
  const std::size_t total = regions.completed + regions.low_resolution + regions.unscanned;
  const RegionMap before = regions;
  const VisibilityPredictor predictor(*map_, regions.cells, cfg.visibility);
  const Eigen::Vector3d claim(55.5, 36.5, 0.0);  // past the wall's north end
  const std::size_t changed = claim_predicted_scans(regions, predictor, {claim}, cfg.regions);
  EXPECT_GT(changed, 500u);
  EXPECT_EQ(regions.completed + regions.low_resolution + regions.unscanned, total);
  EXPECT_LT(regions.unscanned, before.unscanned);
  EXPECT_GT(regions.completed, before.completed);
  // Only upwards (U → M → C), and C only within the completed radius of the claim.
  for (std::size_t o = 0; o < regions.cells.values.size(); ++o) {
    const Region was = before.cells.values[o], now = regions.cells.values[o];
    EXPECT_GE(static_cast<int>(now), static_cast<int>(was));
    if (now == Region::kCompleted && was != Region::kCompleted) {
      const Eigen::Vector2d c = map_->center_of(regions.cells.index_at(o));
      EXPECT_LT((c - claim.head<2>()).norm(), cfg.regions.completed_radius_m + 1.5);
    }
  }
  // Off the map a claim sees nothing.
  EXPECT_EQ(claim_predicted_scans(regions, predictor, {{900, 900, 0}}, cfg.regions), 0u);
}

// A robot standing on the best spot keeps the others' candidates a footprint away from it.
TEST_F(WallYard, NoCandidateWhereAnotherRobotStands) {
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  const Candidate best = plan_next_scan(input(), cfg).ranked.front();
  const std::vector<Eigen::Vector3d> standing = {best.position};
  PlanInput in = input();
  in.occupied = &standing;
  const Plan plan = plan_next_scan(in, cfg);
  ASSERT_FALSE(plan.ranked.empty());
  for (const Candidate& c : plan.ranked) {
    EXPECT_GE((c.position - best.position).head<2>().norm(), cfg.robot_clearance_m);
  }
  // Only a footprint: the next best is still right there, past the wall.
  EXPECT_TRUE(past_the_wall(plan.ranked.front())) << plan.ranked.front().position.transpose();
  const std::vector<Eigen::Vector3d> nowhere = {{std::nan(""), 0, 0}};
  in.occupied = &nowhere;
  EXPECT_THROW(plan_next_scan(in, cfg), std::invalid_argument);
}

TEST_F(WallYard, NoCandidateOrDriveInANoGoZone) {
  // The operator closes the ground around the wall's north end, where the best points lie, and
  // a strip south of the robot that drives around the wall's south end would cross.
  const TargetRegion north = TargetRegion::rectangle({44, 28}, {62, 40});
  const TargetRegion south = TargetRegion::rectangle({30, 0}, {70, 12});
  for (const PlannerPolicy p : {PlannerPolicy::kPaper, PlannerPolicy::kExhaustive}) {
    PlannerConfig cfg;
    cfg.policy = p;
    cfg.no_go = {north, south};
    const Plan plan = plan_next_scan(input(), cfg);
    ASSERT_FALSE(plan.ranked.empty()) << policy_name(p);
    for (const Candidate& c : plan.ranked) {
      EXPECT_FALSE(in_any(cfg.no_go, c.position.head<2>()))
          << policy_name(p) << " " << c.position.transpose();
      ASSERT_FALSE(c.path.empty());
      for (const Eigen::Vector2d& at : c.path) {
        EXPECT_FALSE(in_any(cfg.no_go, at))
            << policy_name(p) << " drives through " << at.transpose();
      }
    }
  }
}

TEST_F(WallYard, NoCandidateNearAPointTheRobotRefused) {
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  const Candidate best = plan_next_scan(input(), cfg).ranked.front();
  const std::vector<Eigen::Vector2d> refused = {best.position.head<2>()};
  PlanInput in = input();
  in.refused = &refused;
  const Plan plan = plan_next_scan(in, cfg);
  ASSERT_FALSE(plan.ranked.empty());
  for (const Candidate& c : plan.ranked) {
    EXPECT_GE((c.position.head<2>() - refused[0]).norm(), cfg.refused_clearance_m);
  }
  const std::vector<Eigen::Vector2d> nowhere = {{std::nan(""), 0}};
  in.refused = &nowhere;
  EXPECT_THROW(plan_next_scan(in, cfg), std::invalid_argument);
}

TEST_F(WallYard, ANonFiniteClaimIsRefused) {
  const std::vector<Eigen::Vector3d> claimed = {{std::nan(""), 1, 0}};
  PlanInput in = input();
  in.claimed = &claimed;
  EXPECT_THROW(plan_next_scan(in, PlannerConfig{}), std::invalid_argument);
  PlannerConfig cfg;
  cfg.claim_separation_m = -1;
  EXPECT_THROW(plan_next_scan(input(), cfg), std::invalid_argument);
}

TEST(PlannerPolicyNames, ParseAndPrintRoundTrip) {
  for (const PlannerPolicy p : kAllPolicies) EXPECT_EQ(parse_policy(policy_name(p)), p);
  EXPECT_EQ(parse_policy("nearest-frontier"), PlannerPolicy::kNearestFrontier);
  EXPECT_FALSE(parse_policy("Paper"));
  EXPECT_FALSE(parse_policy(""));
}

}  // namespace
}  // namespace scanplan

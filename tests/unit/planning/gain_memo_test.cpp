#include "scanplan/planning/gain_memo.hpp"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

#include "scanplan/planning/scan_planner.hpp"
#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

// A 120 m × 70 m site with walls and blocks put down at random (seeded): long enough that a
// scan at one end leaves what the other end's evaluations read unchanged.
World random_site(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> x(5, 115), y(5, 65), len(2, 14), h(0.5, 9), yaw(0, 180);
  std::ostringstream objects;
  for (int k = 0; k < 18; ++k) {
    const double x0 = x(rng), y0 = y(rng), l = len(rng), thick = k % 3 == 0 ? 3.0 : 0.3;
    if (std::hypot(x0 - 10, y0 - 35) < 8) continue;  // keep the start free
    objects << (objects.tellp() > 0 ? "," : "") << R"({"type": "box", "min": [)" << x0 << ", " << y0
            << R"(, 0], "max": [)" << x0 + l << ", " << y0 + thick << ", " << h(rng)
            << R"(], "yaw_deg": )" << yaw(rng) << "}";
  }
  return parse_world(R"({"name": "random_site", "bounds": {"min": [0, 0], "max": [120, 70]},
                         "ground": {"z": 0.0}, "objects": [)" +
                         objects.str() + R"(], "start": [10, 35, 0]})",
                     "random_site");
}

// A random site scanned once from its start.
struct ScannedOnce {
  explicit ScannedOnce(unsigned seed)
      : world(random_site(seed)), caster(world), target(world.target_region()) {
    map.insert_scan(simulate_scan(caster, world.scanner, world.start, 1), world.start.isometry(),
                    {0, 0, world.scanner.mount_height_m});
    points = {{world.start.x, world.start.y}};
  }
  PlanInput input() const {
    return {map, target, points, {world.start.x, world.start.y, world.start.z}};
  }
  World world;
  RayCaster caster;
  TargetRegion target;
  MlsMap map;
  std::vector<Eigen::Vector2d> points;
};

void expect_same(const Plan& fresh, const Plan& memo, const std::string& where) {
  ASSERT_EQ(fresh.ranked.size(), memo.ranked.size()) << where;
  EXPECT_EQ(fresh.evaluations, memo.evaluations) << where;
  for (std::size_t k = 0; k < fresh.ranked.size(); ++k) {
    const Candidate &a = fresh.ranked[k], &b = memo.ranked[k];
    EXPECT_EQ(a.position, b.position) << where << " rank " << k;
    // Bit for bit: a reused evaluation is the evaluation.
    EXPECT_EQ(a.f, b.f) << where << " rank " << k;
    EXPECT_EQ(a.score, b.score) << where << " rank " << k;
    EXPECT_EQ(a.gain_completed_m2, b.gain_completed_m2) << where << " rank " << k;
    EXPECT_EQ(a.overlap_m2, b.overlap_m2) << where << " rank " << k;
  }
}

// A mission of a few scans, each at the exhaustive plan's best point: at every step the plan
// made with the memo is the plan made afresh, for each policy that evaluates F. Then a change
// beyond the scanner's 80 m from part of the site (a post at its far end): the evaluations there
// are reused, the others made anew, and the plan is still the one made afresh.
TEST(GainMemo, PlansWithTheMemoAreThePlansMadeAfresh) {
  for (const unsigned seed : {3u, 11u}) {
    const World world = random_site(seed);
    const RayCaster caster(world);
    const TargetRegion target = world.target_region();
    MlsMap map;
    MlsMap anchored;
    std::vector<Eigen::Vector2d> points;
    Pose at = world.start;
    GainMemo exhaustive_memo, paper_memo;
    PlannerConfig cfg;
    cfg.visibility = VisibilityConfig::from_scanner(world.scanner);
    for (int scan = 1; scan <= 5; ++scan) {
      const PointCloud cloud = simulate_scan(caster, world.scanner, at, scan);
      const Eigen::Vector3d sensor(0, 0, world.scanner.mount_height_m);
      map.insert_scan(cloud, at.isometry(), sensor);
      if (scan % 2 == 1) anchored.insert_scan(cloud, at.isometry(), sensor);
      points.emplace_back(at.x, at.y);
      PlanInput in{map, target, points, {at.x, at.y, at.z}};
      in.anchored = &anchored;
      const std::string where = "seed " + std::to_string(seed) + ", scan " + std::to_string(scan);
      cfg.policy = PlannerPolicy::kExhaustive;
      const Plan fresh = plan_next_scan(in, cfg);
      in.memo = &exhaustive_memo;
      const Plan memo = plan_next_scan(in, cfg);
      expect_same(fresh, memo, where + " exhaustive");
      cfg.policy = PlannerPolicy::kPaper;
      cfg.seed = static_cast<std::uint64_t>(scan);
      in.memo = nullptr;
      const Plan paper_fresh = plan_next_scan(in, cfg);
      in.memo = &paper_memo;
      const Plan paper = plan_next_scan(in, cfg);
      expect_same(paper_fresh, paper, where + " paper");
      if (fresh.ranked.empty()) break;
      const Eigen::Vector3d next = fresh.ranked.front().position;
      at = Pose{next.x(), next.y(), next.z(), 0, 0, 0};
    }
    std::vector<Eigen::Vector3f> post;
    for (float z = 0; z < 2; z += 0.1f) post.emplace_back(118.5f, 68.5f, z);
    map.insert(post);
    PlanInput in{map, target, points, {at.x, at.y, at.z}};
    in.anchored = &anchored;
    cfg.policy = PlannerPolicy::kExhaustive;
    const Plan fresh = plan_next_scan(in, cfg);
    in.memo = &exhaustive_memo;
    const Plan memo = plan_next_scan(in, cfg);
    expect_same(fresh, memo, "seed " + std::to_string(seed) + ", a post far off");
    EXPECT_GT(memo.reused, 0u) << "seed " << seed;
    EXPECT_LT(memo.reused, memo.evaluations) << "seed " << seed;
  }
}

// Nothing changed: the second plan reuses every evaluation; a change of α forgets them all.
TEST(GainMemo, ReusesEverythingWhenNothingChangedAndForgetsOnAnotherAlpha) {
  const ScannedOnce site(5);
  PlannerConfig cfg;
  cfg.policy = PlannerPolicy::kExhaustive;
  GainMemo memo;
  PlanInput in = site.input();
  in.memo = &memo;
  const Plan first = plan_next_scan(in, cfg);
  ASSERT_GT(first.evaluations, 100u);
  EXPECT_EQ(first.reused, 0u);
  const Plan again = plan_next_scan(in, cfg);
  EXPECT_EQ(again.reused, again.evaluations);
  expect_same(first, again, "again");
  cfg.alpha = 0.8;
  const Plan other = plan_next_scan(in, cfg);
  EXPECT_EQ(other.reused, 0u);
  EXPECT_TRUE(memo.cleared());
}

// A plan that finds the memo held by another plan goes without it, and is the same plan.
TEST(GainMemo, APlanWhileAnotherHoldsTheMemoGoesWithout) {
  const ScannedOnce site(7);
  PlannerConfig cfg;
  GainMemo memo;
  PlanInput in = site.input();
  const Plan fresh = plan_next_scan(in, cfg);
  in.memo = &memo;
  std::lock_guard held(memo.in_use());
  const Plan without = plan_next_scan(in, cfg);
  EXPECT_EQ(without.reused, 0u);
  EXPECT_EQ(memo.size(), 0u);
  expect_same(fresh, without, "held");
}

}  // namespace
}  // namespace scanplan

#include <gtest/gtest.h>

#include <algorithm>

#include "scanplan/sim/simulated_scanner.hpp"

namespace scanplan {
namespace {

World flat_world() {
  return parse_world(R"({"name": "flat", "bounds": {"min": [-100, -100], "max": [100, 100]},
                         "ground": {"z": 0}, "objects": [], "start": [0, 0, 0]})",
                     "flat.json");
}

TEST(RayCaster, GroundAndBoxHitsMatchGeometry) {
  World w = flat_world();
  w.boxes.push_back({{5, -1, 0}, {6, 1, 2}, 0, {255, 0, 0}});
  const RayCaster rc(w);
  const auto ground = rc.cast({0, 0, 1}, Eigen::Vector3d(1, 0, -1).normalized(), 0, 100);
  ASSERT_TRUE(ground);
  EXPECT_NEAR(ground->range, std::sqrt(2.0), 1e-9);
  const auto box = rc.cast({0, 0, 1}, {1, 0, 0}, 0, 100);
  ASSERT_TRUE(box);
  EXPECT_NEAR(box->range, 5.0, 1e-9);
  EXPECT_EQ(box->color, (Rgb{255, 0, 0}));
  EXPECT_FALSE(rc.cast({0, 0, 1}, {0, 0, 1}, 0, 100)) << "the sky gives no return";
  EXPECT_FALSE(rc.cast({0, 0, 1}, {1, 0, 0}, 0, 4.9)) << "beyond max range";
}

TEST(RayCaster, YawedBoxIsHitOnItsTurnedFace) {
  World w = flat_world();
  // A 2 m cube centred at (10, 0) turned 45°: its corner points at the origin, 10 − √2 away.
  w.boxes.push_back({{9, -1, 0}, {11, 1, 2}, M_PI / 4, {0, 0, 255}});
  const RayCaster rc(w);
  const auto hit = rc.cast({0, 0, 1}, {1, 0, 0}, 0, 100);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10 - std::sqrt(2.0), 1e-9);
}

TEST(SimulatedScanner, FlatPlaneGivesExpectedCountAndHeights) {
  World w = flat_world();
  w.scanner.range_noise_m = 0;
  w.scanner.rotation_step_deg = 2.0;
  w.scanner.vertical_step_deg = 1.0;
  const PointCloud c = simulate_scan(RayCaster(w), w.scanner, w.start, 7);
  // A beam at elevation e < 0 meets the ground at range h / sin(-e); it counts when that range is
  // within [0.5, 80] m: h = 1 m gives e ≤ −0.7163° and e ≥ −90°. At 1° steps from −90° that is
  // −90..−1 (90 elevations), each for 180 stage angles; the straight-down beam repeats per angle.
  EXPECT_EQ(c.size(), 90u * 180u);
  for (const auto& p : c.points) EXPECT_NEAR(p.z(), 0.0, 1e-4);
}

TEST(SimulatedScanner, SameSeedSameScanAndNoiseHasItsSpread) {
  World w = flat_world();
  w.scanner.rotation_step_deg = 5.0;
  const RayCaster rc(w);
  const PointCloud a = simulate_scan(rc, w.scanner, w.start, 3);
  const PointCloud b = simulate_scan(rc, w.scanner, w.start, 3);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(std::equal(a.points.begin(), a.points.end(), b.points.begin()));
  // Straight-down beams hit at range 1 m: their z spread is the range noise.
  double sum = 0, sum2 = 0;
  int n = 0;
  for (const auto& p : a.points) {
    if (p.head<2>().norm() > 1e-3) continue;
    sum += p.z();
    sum2 += p.z() * p.z();
    ++n;
  }
  ASSERT_GT(n, 50);
  const double sd = std::sqrt(sum2 / n - (sum / n) * (sum / n));
  EXPECT_NEAR(sd, w.scanner.range_noise_m, 0.004);
}

TEST(SimulatedScanner, ThreadCountDoesNotChangeTheScan) {
  World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  w.scanner.rotation_step_deg = 2.0;
  w.scanner.vertical_step_deg = 1.0;
  const RayCaster rc(w);
  const PointCloud serial = simulate_scan(rc, w.scanner, w.start, 42, {}, 1);
  const PointCloud a = simulate_scan(rc, w.scanner, w.start, 42, {}, 2);
  const PointCloud b = simulate_scan(rc, w.scanner, w.start, 42, {}, 2);
  ASSERT_GT(serial.size(), 10000u);
  ASSERT_TRUE(serial.has_colors());
  for (const PointCloud* c : {&a, &b}) {
    ASSERT_EQ(c->size(), serial.size());
    EXPECT_TRUE(std::equal(c->points.begin(), c->points.end(), serial.points.begin()));
    EXPECT_TRUE(std::equal(c->colors.begin(), c->colors.end(), serial.colors.begin()));
  }
  const PointCloud other_seed = simulate_scan(rc, w.scanner, w.start, 43, {}, 2);
  EXPECT_FALSE(
      other_seed.size() == serial.size() &&
      std::equal(other_seed.points.begin(), other_seed.points.end(), serial.points.begin()))
      << "another seed must give other noise";
}

TEST(SimulatedScanner, ProgressIsReportedInOrderAndCanAbort) {
  World w = flat_world();
  w.scanner.rotation_step_deg = 1.0;
  w.scanner.vertical_step_deg = 2.0;
  const RayCaster rc(w);
  std::vector<double> seen;
  const PointCloud full = simulate_scan(
      rc, w.scanner, w.start, 5,
      [&](double f) {
        seen.push_back(f);
        return true;
      },
      2);
  ASSERT_EQ(seen.size(), 120u);  // 360 stage angles, reported every 360 / 100 → 3
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);
  EXPECT_EQ(full.size(), simulate_scan(rc, w.scanner, w.start, 5, {}, 2).size());
  // Stopping after a quarter keeps exactly the stage angles scanned so far.
  const PointCloud part = simulate_scan(
      rc, w.scanner, w.start, 5, [](double f) { return f < 0.25; }, 2);
  EXPECT_GT(part.size(), full.size() / 5);
  EXPECT_LT(part.size(), full.size() / 3);
  EXPECT_TRUE(std::equal(part.points.begin(), part.points.end(), full.points.begin()));
}

}  // namespace
}  // namespace scanplan

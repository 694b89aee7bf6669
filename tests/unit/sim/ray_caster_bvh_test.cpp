// The accelerated caster must give exactly what testing every primitive gives.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scanplan/sim/ray_caster.hpp"

namespace scanplan {
namespace {

void expect_same(const RayCaster& rc, const Eigen::Vector3d& o, const Eigen::Vector3d& d,
                 double min_range, double max_range, int& hits) {
  const auto fast = rc.cast(o, d, min_range, max_range);
  const auto slow = rc.cast_brute_force(o, d, min_range, max_range);
  ASSERT_EQ(fast.has_value(), slow.has_value())
      << "origin " << o.transpose() << " dir " << d.transpose();
  if (!fast) return;
  ++hits;
  ASSERT_NEAR(fast->range, slow->range, 1e-9)
      << "origin " << o.transpose() << " dir " << d.transpose();
  EXPECT_EQ(fast->color, slow->color) << "origin " << o.transpose() << " dir " << d.transpose();
  EXPECT_TRUE(fast->normal.isApprox(slow->normal, 1e-6f));
}

TEST(RayCasterBvh, AgreesWithBruteForceOnCampus) {
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  const RayCaster rc(w);
  ASSERT_GT(rc.primitive_count(), 100u);
  std::mt19937_64 rng(20240611);
  std::uniform_real_distribution<double> ux(w.bounds_min.x() - 20, w.bounds_max.x() + 20);
  std::uniform_real_distribution<double> uy(w.bounds_min.y() - 20, w.bounds_max.y() + 20);
  std::uniform_real_distribution<double> uz(0.2, 20.0), u01(0, 1);
  std::normal_distribution<double> n01;
  int hits = 0;
  for (int i = 0; i < 20000; ++i) {
    const Eigen::Vector3d o(ux(rng), uy(rng), w.ground_height(0, 0) + uz(rng));
    Eigen::Vector3d d(n01(rng), n01(rng), n01(rng));
    // A quarter of the rays are exactly level, as the scanner's horizontal beam is.
    if (i % 4 == 0) d.z() = 0;
    d.normalize();
    const double min_range = u01(rng) < 0.5 ? 0.0 : 0.5;
    const double max_range = u01(rng) < 0.5 ? 80.0 : 400.0;
    expect_same(rc, o, d, min_range, max_range, hits);
    if (HasFatalFailure()) return;
  }
  // About half the rays point skywards and many of those miss.
  EXPECT_GT(hits, 8000) << "too few rays hit anything to compare";
}

TEST(RayCasterBvh, AgreesWithBruteForceForScannerBeams) {
  // A coarse scan from several places, beams exactly as the scanner casts them (level beams,
  // straight down, grazing the tops of 1 m objects from a 1 m mount).
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  const RayCaster rc(w);
  int hits = 0;
  for (const Eigen::Vector2d& xy : {Eigen::Vector2d(80, 45), Eigen::Vector2d(100, 70),
                                    Eigen::Vector2d(150, 120), Eigen::Vector2d(56, 68)}) {
    const Eigen::Vector3d sensor(xy.x(), xy.y(), w.ground_height(xy.x(), xy.y()) + 1.0);
    for (int r = 0; r < 360; r += 7) {
      for (int v = -180; v <= 180; v += 3) {
        const double az = deg2rad(r), el = deg2rad(v * 0.5);
        const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az),
                                std::sin(el));
        expect_same(rc, sensor, d, 0.5, 80.0, hits);
        if (HasFatalFailure()) return;
      }
    }
  }
  EXPECT_GT(hits, 4000);
}

}  // namespace
}  // namespace scanplan

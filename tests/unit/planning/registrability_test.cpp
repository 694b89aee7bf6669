// The planner's forecast of the scan matcher (issue 15): how much of a scan from a candidate
// would land on the anchored map, and whether the walls it would see there fix x, y and yaw.
#include "scanplan/planning/registrability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

namespace scanplan {
namespace {

using Segment = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// Flat ground over [0, 60)² below `ground_max_x`, and 3 m walls along the segments.
MlsMap yard_with(const std::vector<Segment>& walls, double ground_max_x = 60) {
  std::vector<Eigen::Vector3f> points;
  for (double x = 0.25; x < ground_max_x; x += 0.5) {
    for (double y = 0.25; y < 60; y += 0.5) {
      points.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
    }
  }
  for (const auto& [a, b] : walls) {
    const int steps = static_cast<int>((b - a).norm() / 0.25);
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
      for (double z = 0; z <= 3.0; z += 0.25) {
        points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(z));
      }
    }
  }
  MlsMap map;
  map.insert(points);
  return map;
}

constexpr int kSide = 60;

// What a scan from the centre of cell (30, 30) is taken to see: every cell within 25 m.
Registrability forecast_at_centre(const MlsMap& anchored, const RegistrabilityConfig& cfg = {}) {
  const RegistrabilityField field(anchored, {0, 0}, kSide, kSide, cfg);
  RegistrabilityField::Forecast f(field);
  for (int j = 0; j < kSide; ++j) {
    for (int i = 0; i < kSide; ++i) {
      const int di = i - 30, dj = j - 30;
      if (di * di + dj * dj <= 25 * 25) f.add(static_cast<std::uint32_t>(j * kSide + i), di, dj);
    }
  }
  return f.result();
}

TEST(Registrability, ACorridorLeavesThePoseFreeAlongItCrossingWallsFixIt) {
  // Two parallel walls: nothing stops a slide along x.
  const Registrability corridor =
      forecast_at_centre(yard_with({{{5, 20.5}, {55, 20.5}}, {{5, 40.5}, {55, 40.5}}}));
  // One of them turned across: every direction and the yaw are held.
  const Registrability crossing =
      forecast_at_centre(yard_with({{{5, 20.5}, {55, 20.5}}, {{20.5, 5}, {20.5, 55}}}));
  const RegistrabilityConfig defaults;
  EXPECT_LT(corridor.pose_fixing, 0.1 * defaults.min_pose_fixing);
  EXPECT_GT(crossing.pose_fixing, defaults.min_pose_fixing);
  EXPECT_LT(corridor.factor, 0.1);
  EXPECT_EQ(crossing.factor, 1.0);
  // Both scans see the map all round.
  EXPECT_NEAR(corridor.overlap_share, 1.0, 1e-9);
  EXPECT_NEAR(crossing.overlap_share, 1.0, 1e-9);
}

TEST(Registrability, TheOverlapIsTheShareOfTheScanOnTheAnchoredMap) {
  const std::vector<Segment> walls = {{{5, 20.5}, {55, 20.5}}, {{20.5, 5}, {20.5, 55}}};
  // Anchored ground only west of the scanner: half of what it sees, by symmetry.
  const Registrability half = forecast_at_centre(yard_with(walls, 30));
  EXPECT_NEAR(half.overlap_share, 0.5, 0.05);
  // Nothing anchored: nothing to match, the least share of the score.
  const RegistrabilityConfig cfg;
  const Registrability none = forecast_at_centre(MlsMap{}, cfg);
  EXPECT_EQ(none.overlap_share, 0.0);
  EXPECT_EQ(none.pose_fixing, 0.0);
  EXPECT_EQ(none.factor, cfg.floor_share);
  // Switched off, the forecast is still made but costs nothing.
  RegistrabilityConfig off;
  off.enabled = false;
  EXPECT_EQ(forecast_at_centre(MlsMap{}, off).factor, 1.0);
}

}  // namespace
}  // namespace scanplan

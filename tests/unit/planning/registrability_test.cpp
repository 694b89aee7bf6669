// The planner's forecast of the scan matcher (issue 15): how much of a scan from a candidate
// would land on the anchored map, and whether the walls it would see there fix x, y and yaw.
#include "scanplan/planning/registrability.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <utility>
#include <vector>

namespace scanplan {
namespace {

using Segment = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// Flat ground over [0, 60)² below `ground_max_x`, a point every `ground_step_m` (densely
// enough for every new point to have one within the matcher's 0.3 m), and 3 m walls along the
// segments.
// A wall and where the scanner that measured it stood (none: unknown).
struct Wall {
  Segment line;
  std::optional<Eigen::Vector2d> seen_from;
};

// Flat ground over [0, 60)² below `ground_max_x`, a point every `ground_step_m` (densely
// enough for every new point to have one within the matcher's 0.3 m), and 3 m walls.
MlsMap yard_with(const std::vector<Wall>& walls, double ground_max_x = 60,
                 double ground_step_m = 0.1) {
  std::vector<Eigen::Vector3f> ground;
  for (double x = ground_step_m / 2; x < ground_max_x; x += ground_step_m) {
    for (double y = ground_step_m / 2; y < 60; y += ground_step_m) {
      ground.emplace_back(static_cast<float>(x), static_cast<float>(y), 0.0f);
    }
  }
  MlsMap map;
  map.insert(ground);
  for (const auto& [line, seen_from] : walls) {
    const auto& [a, b] = line;
    std::vector<Eigen::Vector3f> points;
    const int steps = static_cast<int>((b - a).norm() / 0.25);
    for (int k = 0; k <= steps; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / steps);
      for (double z = 0; z <= 3.0; z += 0.25) {
        points.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()),
                            static_cast<float>(z));
      }
    }
    map.insert(points, seen_from);
  }
  return map;
}

MlsMap yard_with(const std::vector<Segment>& walls, double ground_max_x = 60,
                 double ground_step_m = 0.1) {
  std::vector<Wall> unknown;
  for (const Segment& w : walls) unknown.push_back({w, std::nullopt});
  return yard_with(unknown, ground_max_x, ground_step_m);
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

// A building's far face, which the map holds from a scan beyond it, is not what a scan from
// this side meets: the street stays a corridor. On the campus, a scan south of a building whose
// east face alone was mapped slid 2.6 m along the one wall it shared with the map; the forecast
// had counted the east face (and the corner cells next to the scanner) as fixing it.
TEST(Registrability, AWallSeenFromTheOtherSideDoesNotFixTheScan) {
  const Segment north = {{5, 20.5}, {55, 20.5}}, south = {{5, 40.5}, {55, 40.5}};
  const Segment across = {{50.5, 21}, {50.5, 40}};
  const Eigen::Vector2d here(30.5, 30.5), beyond(58.5, 30.5);
  const RegistrabilityConfig defaults;
  // Measured from beyond it (x 58.5): the scan at x 30.5 would meet the building's west face.
  const Registrability far_face =
      forecast_at_centre(yard_with({{north, here}, {south, here}, {across, beyond}}));
  // (What is left: the street's cells at the junction, which count as corners.)
  EXPECT_LT(far_face.pose_fixing, 0.25 * defaults.min_pose_fixing);
  EXPECT_LT(far_face.factor, 0.1);
  // Measured from this side: it fixes x.
  const Registrability near_face =
      forecast_at_centre(yard_with({{north, here}, {south, here}, {across, here}}));
  EXPECT_GT(near_face.pose_fixing, defaults.min_pose_fixing);
  EXPECT_EQ(near_face.factor, 1.0);
  // Where it was measured from is not known: counted (and its corners whole: which way they
  // jut is not known either).
  RegistrabilityConfig whole_corners;
  whole_corners.corner_faces = false;
  EXPECT_NEAR(
      forecast_at_centre(yard_with({north, south, across})).pose_fixing,
      forecast_at_centre(yard_with({{north, here}, {south, here}, {across, here}}), whole_corners)
          .pose_fixing,
      1e-9);
  // A post measured from beyond it (no one direction: every direction fixed alike) is met
  // from within a right angle of where it was seen.
  const Segment post = {{50.5, 30}, {50.5, 31}};
  const Registrability post_behind =
      forecast_at_centre(yard_with({{north, here}, {south, here}, {post, beyond}}));
  const Registrability post_in_front =
      forecast_at_centre(yard_with({{north, here}, {south, here}, {post, here}}));
  EXPECT_LT(post_behind.pose_fixing, 0.1 * post_in_front.pose_fixing);
}

// A wall met end-on from afar holds points only where the stage's azimuth steps cross it: a row
// of single wall cells a few cells apart. Each alone looks like a post, which fixes every
// direction; together they are one wall, which fixes the pose across itself only. Measured
// whole, a wall a few degrees off the grid steps through its cells, and each step looked like
// a corner. On the campus a building's 12°-turned face made the street before it look
// registrable, and every scan planned there was refused as a corridor.
TEST(Registrability, AWallTurnedOffTheGridOrMetEndOnIsAWall) {
  const Segment street = {{5, 20.5}, {55, 20.5}};
  const Eigen::Vector2d here(30.5, 30.5);
  // Columns every 3 m along a line turned 12°, each within one cell.
  const double slope = std::tan(12.0 * M_PI / 180);
  std::vector<Segment> columns;
  for (double x = 8.3; x < 52; x += 3) {
    const double y = 35.3 + slope * (x - 8.3);
    columns.push_back({{x, y}, {x + 0.3, y}});
  }
  const auto with_columns = [&](const Eigen::Vector2d& seen_from) {
    std::vector<Wall> walls = {{street, here}};
    for (const Segment& c : columns) walls.push_back({c, seen_from});
    return walls;
  };
  // Seen from far along their line (the face's corner), and from across it.
  const Eigen::Vector2d along(90, 35.3 + slope * (90 - 8.3)), across(30, 5);
  RegistrabilityConfig posts;
  posts.wall_line_radius_cells = 0;
  const RegistrabilityConfig defaults;
  const MlsMap end_on = yard_with(with_columns(along));
  const Registrability as_posts = forecast_at_centre(end_on, posts);
  const Registrability as_wall = forecast_at_centre(end_on, defaults);
  // The street alone leaves x free; a wall turned 12° from it fixes x by sin² 12° of what it
  // fixes across, posts as much as across.
  EXPECT_LT(forecast_at_centre(yard_with(std::vector<Wall>{{street, here}})).pose_fixing, 1e-6);
  EXPECT_LT(as_wall.pose_fixing, 0.2 * as_posts.pose_fixing);
  EXPECT_LT(as_wall.factor, as_posts.factor);
  // Measured whole from in front, the same face steps through its cells: it still fixes x
  // only by sin² 12° of what it fixes across.
  const Segment face = {columns.front().first, columns.back().first};
  const MlsMap stepped = yard_with(std::vector<Wall>{{street, here}, {face, here}});
  const double as_corners = forecast_at_centre(stepped, posts).pose_fixing;
  EXPECT_GT(as_corners, defaults.min_pose_fixing);  // the L at every step a corner
  EXPECT_LT(forecast_at_centre(stepped, defaults).pose_fixing, 0.2 * as_corners);
  // Posts in a row met from the side are posts: a scan there meets each of them.
  EXPECT_NEAR(forecast_at_centre(yard_with(with_columns(across)), defaults).pose_fixing,
              forecast_at_centre(yard_with(with_columns(across)), posts).pose_fixing, 1e-12);
}

// A building's corner fixes the pose along both of its faces only for a scan that sees both; a
// scan beside one face (past the line of the other) meets that face alone and may slide along
// it. On the campus the south building's corner gave scans in the strip before its south face
// 86 % of their forecast along the strip, and every scan planned there was refused as a
// corridor.
TEST(Registrability, ACornerFixesBothDirectionsOnlyWhereBothFacesAreSeen) {
  const Eigen::Vector2d scanner(18.5, 24.5);  // south-west of both corners below
  RegistrabilityConfig faces, whole;
  whole.corner_faces = false;
  // The corner at (25, 36): the scan at (30.5, 30.5) stands east of the west face's line and
  // meets only the south face.
  const MlsMap beside = yard_with(
      std::vector<Wall>{{{{25, 36}, {55, 36}}, scanner}, {{{25, 36}, {25, 55}}, scanner}});
  const Registrability one_face = forecast_at_centre(beside, faces);
  const Registrability counted_whole = forecast_at_centre(beside, whole);
  EXPECT_LT(one_face.pose_fixing, 0.1 * faces.min_pose_fixing);
  EXPECT_LT(one_face.factor, 0.1);
  EXPECT_GT(counted_whole.pose_fixing, 3 * one_face.pose_fixing);
  // The corner at (33, 36): the scan sees both faces, and the corner fixes every direction as
  // before.
  const MlsMap before = yard_with(
      std::vector<Wall>{{{{33, 36}, {55, 36}}, scanner}, {{{33, 36}, {33, 55}}, scanner}});
  const double both_faces = forecast_at_centre(before, faces).pose_fixing;
  EXPECT_GT(both_faces, 10 * one_face.pose_fixing);
  EXPECT_NEAR(both_faces, forecast_at_centre(before, whole).pose_fixing, 0.1 * both_faces);
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

// The matcher counts a point on the map when a map point lies within 0.3 m of it: ground
// measured sparsely, or only interpolated between beams, is little to match against however much
// of it the map holds.
TEST(Registrability, SparseGroundAndHeightsBetweenBeamsAreLittleToMatchAgainst) {
  const std::vector<Segment> walls = {{{5, 20.5}, {55, 20.5}}, {{20.5, 5}, {20.5, 55}}};
  // Four points a 1 m cell: a new point has one within 0.3 m by 1 − exp(−4 π 0.09).
  const Registrability sparse = forecast_at_centre(yard_with(walls, 60, 0.5));
  EXPECT_NEAR(sparse.overlap_share, 1 - std::exp(-4 * M_PI * 0.09), 0.02);

  // One scan's ground returns in two rings, at 4 m and 12 m of every degree: the cells between
  // are filled with heights interpolated between the beams, with no point in them.
  PointCloud scan;
  for (int a = 0; a < 360; ++a) {
    const double t = a * M_PI / 180;
    for (const double r : {4.0, 12.0}) {
      scan.push_back({static_cast<float>(r * std::cos(t)), static_cast<float>(r * std::sin(t)), 0},
                     {1, 2, 3});
    }
  }
  MlsMap rings;
  rings.insert_scan(scan, Eigen::Isometry3d(Eigen::Translation3d(30.5, 30.5, 0)),
                    Eigen::Vector3d(0, 0, 1));
  const MlsCell* between = rings.cell(rings.index_of(38.5, 30.5));
  ASSERT_NE(between, nullptr);
  ASSERT_TRUE(between->interpolated);
  // Counted whole, the cells from 4 to 12 m alone would be ~40 % of what the scan sees.
  EXPECT_LT(forecast_at_centre(rings).overlap_share, 0.2);
}

// With odometry drifting 2 % of the drive and 0.3° per 10 m, the matcher's ±6 m search holds
// 3σ of the pose up to 100 m of driving; beyond, the share falls as 1 / drive.
TEST(Registrability, TheDriveThereMustStayWithinTheMatchersSearch) {
  const RegistrabilityConfig cfg;
  DriveDrift drift;
  drift.xy_per_m = 0.02;
  drift.yaw_deg_per_m = 0.03;
  EXPECT_EQ(drive_reach(drift, 0, cfg), 1.0);
  EXPECT_EQ(drive_reach(drift, 99, cfg), 1.0);
  EXPECT_NEAR(drive_reach(drift, 150, cfg), 100.0 / 150, 1e-9);
  EXPECT_NEAR(drive_reach(drift, 300, cfg), 100.0 / 300, 1e-9);
  // A robot whose latest scan the map could not place starts 2 m / 3° uncertain: its heading
  // swings every metre of the drive sideways, and even a short drive is beyond the search.
  drift.start_xy_m = 2;
  drift.start_yaw_deg = 3;
  const double xy_at_40 = std::sqrt(4 + 0.8 * 0.8 + std::pow(40 * 3 * M_PI / 180, 2));
  EXPECT_NEAR(drive_reach(drift, 40, cfg), 6 / (3 * xy_at_40), 1e-9);
  EXPECT_LT(drive_reach(drift, 40, cfg), drive_reach(drift, 10, cfg));
  // A robot beyond the search already (10 m σ): the drive costs it what it adds.
  DriveDrift lost;
  lost.start_xy_m = 10;
  lost.xy_per_m = 0.02;
  EXPECT_EQ(drive_reach(lost, 0, cfg), 1.0);
  EXPECT_NEAR(drive_reach(lost, 100, cfg), 10 / std::hypot(10.0, 2.0), 1e-9);
  // The heading alone: 0.03°/m reaches 30° at 3σ after 333 m.
  DriveDrift turning;
  turning.yaw_deg_per_m = 0.03;
  EXPECT_NEAR(drive_reach(turning, 500, cfg), 30 / (3 * 15.0), 1e-9);
}

}  // namespace
}  // namespace scanplan

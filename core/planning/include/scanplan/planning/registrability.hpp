#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/mapping/mls_map.hpp"

namespace scanplan {

// Whether the scan matcher will be able to place a scan taken at a candidate point (issue 15):
// the planner's forecast of the matcher's sanity check (AlignmentQuality: the share of the scan
// on the map, and the weakest constraint its surfaces put on the pose). A scan the check refuses
// keeps the pose the robot reports, metres off; a plan that goes on from there builds on sand.
struct RegistrabilityConfig {
  // Off: candidates are ranked by the policy's score alone (the forecast is still made).
  bool enabled = true;
  // A candidate is registrable when both forecasts reach these; below, it keeps the share s²
  // of its F, s = min(overlap_share / min_overlap_share, pose_fixing / min_pose_fixing), at
  // least floor_share. Calibrated on the campus loop against the match outcomes
  // (docs/planner.md): below an overlap share of 0.09 no match was applied.
  double min_overlap_share = 0.3;
  // The matcher counts a point as on the map when a map point lies this near it
  // (RegistrationConfig::inlier_distance_m). A cell of the anchored map holding n measured points
  // counts as overlap by the chance that one lies this near a new point in it, 1 − exp(−n·π·d² /
  // cell area): the ground 40 m from every scanner holds a point every few metres, or only
  // heights interpolated between beams, and a scan there found 3–10 % of its points on the map
  // where counting such cells whole forecast 30–60 % (issue 15).
  double inlier_distance_m = 0.3;
  double min_pose_fixing = 0.002;
  // Where the scans' poses come from absolute fixes (σ 1 m, 5°, no odometry between them), a
  // match starts metres and degrees off with nothing nearer to go by, and before weak walls GICP
  // settles elsewhere: a candidate then needs this many times min_pose_fixing
  // (MissionPipeline). On the campus with absolute fixes (30 scans, seeds 1–5) matches at
  // forecasts of 0.002–0.004 were refused a third of the time (one street, one facade), above
  // one in nine; with drifting odometry, whose match starts decimetres off, the higher threshold
  // cost coverage and placed no more scans right (docs/benchmarks.md, 2026-12-04).
  double absolute_fix_factor = 2.0;
  double floor_share = 0.05;
  // A cell of the anchored map holding a surface at least this deep is a wall: it fixes the
  // pose across itself. Kerbs and low steps fix little; ground fixes only z, roll and pitch.
  double wall_min_extent_m = 0.5;
  // A wall's direction is that of the walls within this many cells of it.
  int wall_radius_cells = 2;
  // Where the walls within wall_radius_cells show no one direction, that of a straight line of
  // wall cells through the cell and on both sides of it within this many cells. A wall a few
  // degrees off the grid steps through its cells (an L of three cells looks like a corner), and
  // one met end-on from afar holds points only where the stage's azimuth steps cross it, a row
  // of single cells a few apart, each of which alone looks like a post; a corner or a post
  // fixes every direction, a wall only across itself. A row of single cells counts as a wall
  // only when its scanners stood along it (posts in a row met from the side are posts). On the
  // campus a building turned 12° made the strip before its south face, seen end-on from its
  // corner, look registrable, and every scan planned there was refused as a corridor
  // (issue 15). 0: off (the forecast before 2026-12-07).
  int wall_line_radius_cells = 6;
  // Where the walls around a cell show no one direction but two arms of wall leave it (a
  // building's corner), the corner fixes both directions only for a scan that sees both of its
  // faces; from beside one face it fixes the pose across that face alone. On the campus the
  // south building's corner counted as fixing every direction for scans in the strip before its
  // south face, which see only that face, and gave them 86 % of their forecast along the strip:
  // every scan planned there was refused as a corridor (issue 15). Off: a corner fixes every
  // direction for any scan within a right angle of where it was seen (before 2026-12-07).
  bool corner_faces = true;
  // A wall counts only for a scan on the side its scanners stood on (SurfacePatch::seen_from):
  // from the other side the scan meets another face, or none (on the campus, a building's far
  // face made a street look registrable). Off: every wall counts from anywhere (the forecast
  // before 2026-12-07, registrability_bench's baseline).
  bool sided_walls = true;
  // Cells nearer the scanner than this are weighted as if this far: a scan's point density
  // falls with the square of the range, and a wall next to the scanner is not infinitely
  // many points. (The matcher thins both clouds to 0.25 m voxels, which the scanner's 0.5°
  // steps fill out to 28.6 m: weighted alike to there, the forecast ranked right matches above
  // failed ones better in registrability_bench, but with the threshold moved to keep as many
  // right ones, the loop placed fewer scans; docs/benchmarks.md, 2026-12-07.)
  double near_range_m = 3.0;
  // With odometry that drifts (DriveDrift), a candidate a long drive away is reached with a
  // pose 3σ of which may lie beyond the scan matcher's own search (PoseSearchConfig: ±6 m,
  // ±30°). The match must then search wider, where a look-alike one building's depth away (16 m
  // on the campus) fits as well, and is refused or wrong: on the campus with 2 % drift, scans
  // after drives of 100–190 m were placed half as often as after shorter ones (issue 17). Such
  // a candidate keeps the share s² of its F (at least floor_share), s = drive_reach: min(reach_xy_m
  // / 3σ_xy, reach_yaw_deg / 3σ_yaw) after the drive, over the same before it.
  double reach_xy_m = 6.0;
  double reach_yaw_deg = 30.0;
};

// How uncertain a robot's pose will be where it scans next with odometry that drifts with the
// distance driven: the spread it has now (after its latest scan the map placed, the drive
// since) and what each metre of the drive there adds.
struct DriveDrift {
  double start_xy_m = 0, start_yaw_deg = 0;
  double xy_per_m = 0;       // σ of x-y per metre driven (PoseNoise::xy_drift_fraction)
  double yaw_deg_per_m = 0;  // σ of the heading per metre driven
};

// The share s of RegistrabilityConfig::reach_xy_m: 1 when 3σ of the pose after driving
// `travel_m` stays within the matcher's search; for a robot whose pose is beyond the search
// already, the share after the drive over that before it.
double drive_reach(const DriveDrift& drift, double travel_m, const RegistrabilityConfig& config);

// The forecast for one candidate.
struct Registrability {
  // The share of what the scan is predicted to see (weighted by the point density, 1 / r²)
  // that lies on the anchored map: the forecast of the matcher's inlier ratio.
  double overlap_share = 0;
  // The weakest eigenvalue of the x, y, yaw information the anchored walls in view give,
  // per unit of weighted overlap (yaw as a moment over the walls' RMS range, as
  // AlignmentQuality::weakest_constraint does): near zero in a corridor or before one wall.
  double pose_fixing = 0;
  // drive_reach for the drive there (1 without drifting odometry or when the search reaches).
  double reach = 1;
  // The share of its score the candidate keeps (1: registrable).
  double factor = 1;
  // The weakest constraint the map's own points a scan there is predicted to see put on its
  // pose, as the matcher's sanity check judges it (ViewCheckConfig, in the mission pipeline);
  // nothing where not checked. A failed check is counted in `factor`.
  std::optional<double> predicted_constraint;
};

// The anchored map (the scans the matcher trusts; MissionPipeline) rasterised on the planner's
// grid: which cells it holds and, for its walls, the direction their surfaces face. Built once
// per plan; read by many threads.
class RegistrabilityField {
 public:
  RegistrabilityField(const MlsMap& anchored, CellIndex origin, int cols, int rows,
                      const RegistrabilityConfig& config);

  // What a forecast reads (GainMemo): the configuration, and one raster cell.
  std::uint64_t digest() const;
  std::uint64_t cell_digest(std::size_t offset) const;

  // Sums what a candidate sees, cell by cell (raster offsets), then forecasts.
  class Forecast {
   public:
    explicit Forecast(const RegistrabilityField& field) : field_(field) {}
    // A visible cell `o`, (di, dj) cells from the candidate's.
    void add(std::uint32_t o, int di, int dj);
    Registrability result() const;

   private:
    const RegistrabilityField& field_;
    // mapped_: weight on any cell the map holds (pose fixing is per unit of it); on_map_: the
    // same by each cell's odds (the overlap share).
    double seen_ = 0, mapped_ = 0, on_map_ = 0;
    // Weighted sums over the walls seen: Σ T, Σ T·p⊥, Σ p⊥ᵀ·T·p⊥, Σ |p|², Σ w, where T is the
    // wall's normal tensor and p⊥ its position turned by 90° (the yaw lever).
    double t_xx_ = 0, t_xy_ = 0, t_yy_ = 0, tp_x_ = 0, tp_y_ = 0, ptp_ = 0, r2_ = 0, walls_ = 0;
  };

 private:
  struct Cell {
    // n nᵀ of the wall's normal (in the x-y plane); I/2 where the walls around have no one
    // direction (a post, a corner); zero where there is no wall.
    float t_xx = 0, t_xy = 0, t_yy = 0;
    // A corner with two arms of wall (corner_faces): the outward normals of its faces. A scan
    // meets a face only from the side its normal points to.
    float n1x = 0, n1y = 0, n2x = 0, n2y = 0;
    std::uint8_t faces = 0;  // 1 for such a corner (n1, n2 set), else 0
    // The directions (MlsMap's view sectors, from the cell) from which a scan meets the face
    // the map holds here: the side of the wall its scanners stood on (all, where unknown).
    ViewSectors visible_from = 0xFFFF;
    float odds = 0;  // that a new point here has a measured map point within inlier_distance_m
    std::uint8_t mapped = 0, wall = 0;
  };
  // The wall cells within `radius` cells of cell (i, j), it included, and the line they lie
  // on: its normal, where they spread along it several times more than across and, with
  // `max_off_line` (squared cells), lie that near a line through the cell on average and on
  // both sides of it.
  struct WallLine {
    int cells = 0;
    std::optional<Eigen::Vector2d> normal;
  };
  WallLine wall_line(int i, int j, int radius, std::optional<double> max_off_line = {}) const;
  // The offsets of the wall cells within `radius` cells of cell (i, j), it included.
  std::vector<Eigen::Vector2d> wall_offsets(int i, int j, int radius) const;
  // The two arms of wall leaving cell (i, j) within `radius` cells, as unit directions, where
  // each holds two wall cells or more and they are 50–130° apart.
  std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> corner_arms(int i, int j,
                                                                         int radius) const;
  // Marks wall cell `w` at (i, j) a corner with two faces when two arms leave it (corner_faces):
  // their outward normals, from where its scanners stood (`seen`).
  void set_faces(Cell& w, ViewSectors seen, int i, int j) const;
  // Whether a scanner in every sector of `seen` stood nearly along a line with `normal`.
  static bool seen_along(ViewSectors seen, const Eigen::Vector2d& normal);
  // The view sectors a wall cell is met from: those on the side of the wall (its `normal`, for
  // a straight one) its scanners stood on, `seen`.
  static ViewSectors visible_from(ViewSectors seen, const std::optional<Eigen::Vector2d>& normal);

  RegistrabilityConfig config_;
  double cell_m_;
  int cols_, rows_;
  std::vector<Cell> cells_;
};

}  // namespace scanplan

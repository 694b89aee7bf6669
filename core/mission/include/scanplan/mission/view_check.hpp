#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/viewpoints.hpp"
#include "scanplan/planning/scan_planner.hpp"
#include "scanplan/registration/alignment_quality.hpp"

namespace scanplan {

// The planner's forecast of the matcher (RegistrabilityField) works on the map's 1 m cells,
// each weighed alike by 1/r²; the matcher's sanity check counts voxel-thinned points, a tall
// face by its area. On the campus, scans planned a few metres before one long facade passed
// the forecast and were refused by the check as "nearly free in one direction" (13 in 10 runs
// of 60 scans, issue 15). The best candidates are therefore checked once more against the
// map's own points: those a scanner there would see, judged as the matcher judges a match.
struct ViewCheckConfig {
  bool enabled = true;
  // The best this many candidates are checked, at most, until one passes.
  std::size_t candidates = 4;
  // Angular bins of the predicted range image (azimuth and elevation): the scanner's steps
  // (ScannerModel's 0.5° both ways), one return each.
  double bin_deg = 0.5;
  // A map point farther than the nearest surface in its bin by this much (or this share of
  // its range, whichever is more) is hidden behind it; nearer ones are the same surface. A
  // voxel hides the bins it would span seen head-on, but the ground is met at a grazing angle:
  // from 1.5 m up, a ground voxel r away spans what lies up to 0.1·r farther (0.6 · voxel · r /
  // height), so the share is well above that.
  double hidden_m = 0.5;
  double hidden_share = 0.25;
  // Where the viewpoints of the map's points are known, a point on a surface whose normal
  // (turned toward the scanner that saw it) points away from the eye by more than this cosine
  // is on the far side of something solid: it hides, and is not returned.
  double back_face_cos = 0.05;
  // A candidate whose predicted weakest constraint (AlignmentQuality::weakest_constraint over
  // the visible points) falls below this keeps the share s² of its score, s = constraint /
  // min_constraint (at least RegistrabilityConfig::floor_share). Below the matcher's own 0.03:
  // where it checks the restarts (RegistrationConfig::restart_min_constraint) a match the
  // restarts confirm stands. Calibrated on the campus loop (10 runs of 60 scans, the check made
  // and not used, docs/benchmarks.md 2026-12-07): of the 9 matches forecast below 0.02, one was
  // applied (at 0.017); of the 579 at or above it, 567.
  double min_constraint = 0.02;
};

// The points of `map` (thinned to `voxel_m`) that a scanner at `eye` would return within
// `max_range_m`: in each bin the nearest, unless a nearer surface hides it. Each point stands for
// a voxel and hides what lies behind the bins its voxel spans, so that a near wall the thinning
// left holes in still hides what is behind it; far off, where a bin spans several voxels (the
// ground at a grazing angle), only the nearest is returned, as sparse as the scan will be.
// With `views` (where each map point was seen from), points on the far side of a surface are not
// returned (ViewCheckConfig::back_face_cos); the surfaces' normals come from `judge`, one over
// exactly `map`'s points (the one that then judges the view), else from one built here. Throws
// std::invalid_argument for bins that are no angle.
PointCloud visible_points(const PointCloud& map, const Eigen::Vector3f& eye, double voxel_m,
                          double max_range_m, const ViewCheckConfig& config,
                          const Viewpoints& views = {}, const AlignmentJudge* judge = nullptr);

// Checks the best candidates of `plan` in rank order with `constraint` (a candidate's predicted
// weakest constraint; only candidates with a forecast, Candidate::registrability, are checked)
// until the best one passes or `config.candidates` were checked; a candidate that fails keeps
// the share of its score ViewCheckConfig::min_constraint says, on top of its forecast's, and the
// plan is ranked again. Records each check in the candidate's
// Registrability::predicted_constraint.
void check_views(Plan& plan, const std::function<double(const Candidate&)>& constraint,
                 const ViewCheckConfig& config, double floor_share);

}  // namespace scanplan

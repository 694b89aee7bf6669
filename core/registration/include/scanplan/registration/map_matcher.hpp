#pragma once

#include "scanplan/geometry/pose.hpp"
#include "scanplan/registration/ground_level.hpp"
#include "scanplan/registration/registration.hpp"

namespace scanplan {

// A scan matched to the whole map around it lands on it far more than on one other scan: under
// 7 % of its points on the map's surfaces, a match that passed the other checks was wrong 22
// times in 36 on the campus loops with drifting odometry (metres off, a look-alike on the edge
// of what the map holds), from 7 % to 10 % 5 times in 98 (issue 17). Such a scan waits for the
// map to grow around it (MissionPipeline::rematch_refused) or for its neighbours to tie it in.
// Nor is a weakly constrained result believed on the restart check below a weakest constraint of
// 0.01 (RegistrationConfig::restart_min_constraint): on those loops 3 of the 4 map matches it let
// through there were 0.16–1.5 m off, sliding along a street the restarts could not tell apart,
// and later scans matched to them inherited the error; from 0.01 to 0.02, 1 of 8.
inline RegistrationConfig map_registration() {
  RegistrationConfig c;
  c.min_inlier_ratio = 0.07;
  c.restart_min_constraint = 0.01;
  c.range_by_direction = true;
  return c;
}

struct MapMatchConfig {
  // Beyond the paper (§4.3 uses NDT then line-segment ICP, still selectable): scans the
  // planner places 30–40 m apart need the wide basin of a search and GICP's accuracy.
  Method method = Method::kSearchGicp;
  // Its lengths are fitted to the new scan's range (adapt_to_scene), not to the map's: the map
  // around the scan reaches target_radius_m whatever the scanner saw.
  RegistrationConfig registration = map_registration();
  // Map points farther than this from the reported position cannot overlap the new scan much,
  // and only slow the match down.
  double target_radius_m = 60.0;
  // A correction larger than this is not believed even when the solver converged: the pose
  // sensors are not that wrong (DESIGN.md: σ 1 m, 5°), so it would be a false match.
  double max_correction_m = 6.0;
  double max_correction_deg = 25.0;
  // A fit outside the 99 % ellipsoid of the odometry prior is a look-alike (match_to_map) unless
  // the scan lies on the map as firmly as no look-alike did: this share of its points on the
  // map and walls pinning it this well (AlignmentQuality::weakest_constraint). The look-alikes
  // that gate was set by had 7.7–8.6 % inliers; over the campus loops (4,000 matches, 2026-12-04)
  // no fit metres off passed the sanity check with a quarter of its points on the map, while the
  // gate refused 17 right ones at 3.4–8σ, 36–58 % inliers and a weakest constraint of 0.07–0.19
  // but two: the odometry prior had taken the planner's path, and the robot drove round a
  // platform the map showed a ramp onto (88 m for 23 m planned).
  double far_fit_min_inlier_ratio = 0.25;
  double far_fit_min_constraint = 0.06;
  // A refused match leaves x, y and yaw as reported but sets z by the ground (ground_offset),
  // when that moves it no more than this (3σ of the reported height, DESIGN.md).
  bool level_refused = true;
  double max_level_m = 1.0;
  GroundLevelConfig ground;
};

struct MapMatch {
  // Where the scan goes in the map: corrected, or the reported pose on failure (its z set by
  // the ground when `levelled`).
  Pose placed;
  // Where the matcher's result would put the scan, applied or not (the reported pose when no
  // alignment ran): what a refused match proposed, for whoever studies the refusals.
  Pose proposed;
  RegistrationResult result;
  bool applied = false;  // whether `placed` is the matcher's correction
  // The result's AlignmentQuality::information with its x-y turned into the map frame (zero
  // when no alignment settled), for the pose graph.
  Eigen::Matrix4d information = Eigen::Matrix4d::Zero();
  bool levelled = false;  // refused, and `placed` raised or lowered onto the map's ground
};

// The pipeline hook of paper §4: the new scan (its own frame) matched against the map built so
// far (map frame), starting from the reported pose. The match runs in a levelled frame at the
// reported position, so the 4-DOF solver turns about the true vertical and keeps the measured
// roll and pitch. `views`: where the map's points were seen from (map frame) and where the scan's
// scanner sits in its own frame; with them the faces of thin surfaces are told apart
// (register_scans).
MapMatch match_to_map(const PointCloud& map_points, const PointCloud& scan, const Pose& reported,
                      const MapMatchConfig& config = {}, const MatchViews& views = {});

}  // namespace scanplan

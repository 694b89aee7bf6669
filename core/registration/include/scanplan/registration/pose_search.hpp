#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// The coarse stage of scan-to-map matching: an exhaustive search over x, y and yaw around the
// reported pose (correlative matching, Olson 2009, here over a 3-D likelihood grid). Beyond the
// paper: its NDT needs the start within a cell or so; a pose sensor wrong by 2 m and 10° at
// once, with 30–40 m between scans, is often outside every local method's basin (issue 15).
// The search covers the whole pose uncertainty, and returns several distinct peaks, since the
// best-scoring one at coarse resolution is not always the true pose: a local method refines
// each and the results are compared.
struct PoseSearchConfig {
  // Half-widths of the search: ±3σ of the pose sensors (DESIGN.md's σ 1 m, 5° with room for
  // the benchmark's 2 m, 10°). Not scaled with the scene: they are the sensors' uncertainty.
  double xy_range_m = 6.0;
  double yaw_range_deg = 30.0;
  // The likelihood grid's cube side; translations are tried at this step. Each target point
  // makes its cube and those around it likely, falling off as a Gaussian of this σ, so that a
  // pose between two steps still scores near its peak.
  double cell_m = 0.5;
  double yaw_step_deg = 1.5;
  // The source is thinned to cubes of this side and at most this many points are scored.
  double source_voxel_m = 1.0;
  int max_source_points = 1500;
  // Peaks returned, best first; a peak within these of a better one is the same peak.
  int hypotheses = 3;
  double min_separation_m = 1.5;
  double min_separation_deg = 5.0;
  // Above 0, search-gicp refines every peak, and when two distinct ones both pass the sanity
  // check, the lesser with at least this share of the better one's inliers, the match is
  // refused as ambiguous: a search wider than the spacing of a repeated structure (a row of
  // equal buildings, parked cars) finds the same fit shifted by one period.
  double ambiguity_ratio = 0;
  // How far off the initial pose is likely to be (σ, from the odometry since the robot's last
  // placed scan: ScanGraph::prior_uncertainty); 0: nothing known, every pose in the range
  // equally likely. With it, peaks are ranked, and search-gicp's refinements chosen, by their
  // score times the prior's density relative to its centre (prior_weight): a look-alike one
  // building's depth away (16 m on the campus), which at coarse resolution may score a little
  // better than the true pose 2 m from where the odometry put the robot, no longer comes first.
  double prior_sigma_xy_m = 0;
  double prior_sigma_yaw_deg = 0;
};

// exp(−½ (d² / σ_xy² + θ² / σ_yaw²)) for a pose d metres and θ off `initial` (each term only
// with its σ set): 1 at the initial pose and without a prior.
double prior_weight(const PoseSearchConfig& config, const Eigen::Isometry3d& initial,
                    const Eigen::Isometry3d& pose);

struct PoseHypothesis {
  Eigen::Isometry3d transform;  // maps source into target
  double score;                 // mean likelihood of the source points, 0–1
};

// Distinct poses of `source` in `target` around `initial`, best first (at most
// config.hypotheses; none when either cloud is empty). The search turns about the source
// origin's position under `initial` and about the target's z axis (a levelled target: roll and
// pitch of `initial` are kept), and leaves z to the refinement.
std::vector<PoseHypothesis> search_poses(const PointCloud& target, const PointCloud& source,
                                         const Eigen::Isometry3d& initial,
                                         const PoseSearchConfig& config = {});

}  // namespace scanplan

#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <functional>
#include <optional>
#include <string_view>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/registration/gicp.hpp"
#include "scanplan/registration/line_segment_icp.hpp"
#include "scanplan/registration/narrower_ndt.hpp"
#include "scanplan/registration/pose_search.hpp"
#include "scanplan/registration/registration_result.hpp"

namespace scanplan {

// Scan matching (paper §4, DESIGN.md "Scan matching"). PCL's matchers, the baselines, live in
// scanplan_registration_pcl and go through the same register_with, so that they run on the same
// input and are scored the same way.
enum class Method {
  kNdtIcp,  // narrower NDT, then line-segment ICP (paper §4.3): the default
  kNdt,     // narrower NDT alone (§4.2)
  kIcp,     // line-segment ICP alone (§4.1)
  // Beyond the paper (issue 15): coarse-to-fine GICP from the initial pose, and the same from
  // each peak of a search over the whole pose uncertainty (pose_search.hpp), the best result
  // kept. search-gicp is what scan-to-map matching uses.
  kGicp,
  kSearchGicp,
};

// "ndt-icp", "ndt", "icp", "gicp", "search-gicp"; nullopt for anything else.
std::optional<Method> parse_method(std::string_view name);
std::string_view method_name(Method method);

// Everything a match can be tuned by, as plain data. Lengths are for outdoor scans like the
// paper's (tens of metres); with adapt_to_scene they shrink for shorter-range data.
// IcpConfig: the source is thinned further, to 0.75 m, for speed: on the campus benchmark that
// costs no success and a third of the ICP time against 0.5 m.
struct RegistrationConfig {
  Dof dof = Dof::k4;  // paper §4.3: the inclination sensor fixes roll and pitch
  // Both clouds are first thinned to one point per cube of this side (voxel_downsample; 0: not
  // thinned), so that every method sees the same points and the dense ground at the scanner's
  // feet does not outweigh the walls.
  double voxel_m = 0.25;
  // Fit the lengths to the scene, measured as scene_range_m() of the target (before thinning):
  //  - NDT cells: the paper's 20/15/10 m (§4.2) are taken to suit a scene range of
  //    paper_scene_range_m and are scaled by min(1, range / paper_scene_range_m). Our simulated
  //    campus scans (range 13–22 m) get 5–9 m first cells; with the paper's cells as they are,
  //    the coarse Gaussians average what one scan sees of a 20 m cube against what the other
  //    sees and the optimum lands metres off (docs/benchmarks.md). The 3DTK sample (range
  //    6–8 m) gets 2.4–3.3 m.
  //  - every other length (voxel, ICP distances, the baselines' settings, score and sanity
  //    distances) is
  //    tuned for the campus and scaled by min(1, range / reference_scene_range_m).
  bool adapt_to_scene = true;
  // The scene range as open_range_m instead of scene_range_m. Scans taken next to a wall have
  // most of their points on it: over all points, campus scans came out at 6–10 m (13–22 m in
  // the open), their lengths shrank to 0.5–0.8 of the campus's, and GICP started at the truth
  // slid 10–25 cm along the streets there (loop matches 0.4–1.6 m off). The paper's methods and
  // their tests keep the measure their cells were set by; map and pairwise matching use this.
  bool range_by_direction = false;
  double paper_scene_range_m = 50.0;
  double reference_scene_range_m = 12.0;

  NdtConfig ndt;
  IcpConfig icp{.source_voxel_m = 0.75};
  GicpConfig gicp;
  // search-gicp's coarse stage; its ranges are the pose sensors' and are not scaled.
  PoseSearchConfig search;

  // Eq. 2 score: each squared distance is truncated at this (see evaluate_alignment).
  double score_max_distance_m = 1.0;
  // The sanity check behind `converged`: a solver that stopped on its tolerances has still
  // failed when fewer than min_inlier_ratio of the source points found a target point within
  // inlier_distance_m (the clouds hardly overlap), or when the matched surfaces do not pin the
  // pose down in every direction (AlignmentQuality::weakest_constraint below min_constraint: a
  // corridor, or a single wall and the ground, along which a result slid metres off fits as
  // well as the true one). Calibrated on labelled results (registration_bench --far 30
  // --features, seed 6: ndt-icp, gicp and search-gicp on 110 campus pairs 10–40 m apart;
  // docs/benchmarks.md): 4 of 23 results that settled wrong pass (all ndt-icp, all 4 m off or
  // more), 2 of 295 right ones are refused. A share of inliers is no test of rightness at the
  // planner's spacing: right matches of scans 35 m apart have as few as 7 %; nor is how close
  // the overlap lies to the target's surfaces, since the wrong results slide along them.
  // In 6 DOF the weakest of six directions is weaker than the weakest of four (the tilt rests
  // on the ground alone): the earlier 0.01 stays, uncalibrated (the campus is matched in 4 DOF;
  // the 3DTK scans, matched in 6, give 0.014 at their reference).
  double inlier_distance_m = 0.3;
  double min_inlier_ratio = 0.03;
  double min_constraint = 0.03;
  double min_constraint_6dof = 0.01;
  // search-gicp: a result refused for its weakest constraint alone is believed after all when
  // GICP restarted from it moved restart_shift_m along x and y and turned restart_turn_deg
  // either way comes back within restart_tolerance_m and _deg each time: the weakest-constraint
  // number counts every matched point, the ground's too, and small overlaps with a few walls across
  // score low although they fix the pose; a pose the surfaces leave free stays where it is put.
  // Below restart_min_constraint a result is refused whatever the restarts say: there GICP creeps
  // back along the nearly free direction within the tolerance (2 of 290 loop matches at 0.0041
  // passed 2–3 m off; the right ones start at 0.006, one at 0.0034).
  // Nor is it believed farther than restart_max_shift_m (x-y) from where the match started: weak
  // evidence only where the pose sensors agree (4σ of their 1 m; in the loop the right results
  // it took lay within 3.7 m, a wrong one 5 m off held on restarts in a repeated facade). Not
  // scaled with the scene: it is the sensors'. With drifting odometry the scan graph raises it to
  // 4σ of how far the start may be off (widened in scan_graph.hpp).
  bool restart_check = true;
  double restart_min_constraint = 0.005;
  double restart_max_shift_m = 4.0;
  double restart_shift_m = 1.0;
  double restart_turn_deg = 2.0;
  double restart_tolerance_m = 0.05;
  double restart_tolerance_deg = 0.15;  // 5 cm at 20 m
  // Fewer points than this in either cloud after thinning: no match is attempted.
  std::size_t min_points = 30;
};

// How far the scanner sees in `cloud`, whose origin is taken as the sensor: the 90th percentile
// of the point ranges. (Not the median: a scanner whose fan sweeps the ground at its feet puts
// half its points within a couple of metres even on an open campus.) 0 for an empty cloud.
double scene_range_m(const PointCloud& cloud);
// How far the scanner sees where its view is open: each 10° sector of azimuth's 90th percentile
// of range, and the 90th percentile of those (over all points when no sector has 20). Unlike
// scene_range_m, a wall beside the scanner that holds most of its points does not shorten it.
double open_range_m(const PointCloud& cloud);

// `config` with every length but the NDT cell sizes multiplied by `factor`.
RegistrationConfig scale_lengths(const RegistrationConfig& config, double factor);

// The factor every length but the NDT cells is scaled by for this target (1 unless
// adapt_to_scene).
double length_scale(const PointCloud& target, const RegistrationConfig& config);

// The configuration register_scans actually uses for this target: scaled when adapt_to_scene.
RegistrationConfig adapted_config(const PointCloud& target, const RegistrationConfig& config);

// One alignment of clouds already thinned, with the configuration already adapted to the scene
// (`length_scale` is the factor it was adapted by): the part that differs between methods.
// Fills transform, iterations, converged and message. `views` are the thinned clouds'
// viewpoints when the caller gave them (unknown otherwise).
using Aligner = std::function<RegistrationResult(
    const PointCloud& target, const PointCloud& source, const Eigen::Isometry3d& initial,
    const RegistrationConfig& adapted, double length_scale, const MatchViews& views)>;

// What every method shares around its alignment: the input checks, the scene adaptation, the
// thinning, the timing, the Eq. 2 score and the sanity check behind `converged`. `method` names
// the result.
RegistrationResult register_with(const PointCloud& target, const PointCloud& source,
                                 const Eigen::Isometry3d& initial, std::string_view method,
                                 const Aligner& align, const RegistrationConfig& config = {},
                                 const MatchViews& views = {});

// Finds the transform that maps `source` into `target`, starting from `initial`. Bad input
// (an empty cloud, too few points, a non-finite initial transform, clouds that do not overlap)
// is not an exception: it gives converged = false with the reason in `message`, and never a
// wrong pose marked converged as far as the sanity check can tell. With `views` (where each
// cloud was seen from, in its own frame) gicp and search-gicp tell the faces of thin surfaces
// apart (GicpConfig::min_normal_agreement); the paper's methods do not use them.
RegistrationResult register_scans(const PointCloud& target, const PointCloud& source,
                                  const Eigen::Isometry3d& initial, Method method = Method::kNdtIcp,
                                  const RegistrationConfig& config = {},
                                  const MatchViews& views = {});

}  // namespace scanplan

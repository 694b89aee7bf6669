#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "scanplan/mission/mission_pipeline.hpp"
#include "scanplan/sim/world.hpp"

namespace scanplan {

struct ClosedLoopConfig {
  PlannerConfig planner;
  PipelineConfig pipeline;
  int max_scans = 13;  // the paper's campus run took 13 scans (§3.5)
  std::uint64_t seed = 1;
  // Stop once this share of the reachable ground is scan-completed (100: never early).
  double stop_at_coverage_pct = 100.0;
  // Scan matching of each new scan against the map so far (paper §4); nothing: scans are placed
  // at the reported pose.
  std::optional<MapMatchConfig> matching = MapMatchConfig{};
  // The pose graph over the scans (with matching on); nothing: each scan stays where its
  // match put it.
  std::optional<ScanGraphConfig> graph = ScanGraphConfig{};
  // The best candidates checked against the map's points (MissionConfig::view_check).
  ViewCheckConfig view_check;
};

// One scan of the loop and the decision taken after it.
struct LoopStep {
  int scan = 0;        // 1-based
  Pose true_pose;      // where the robot really scanned
  Pose reported_pose;  // what the robot's pose sensors said
  Pose matched_pose;   // where matching put the scan (the reported pose when it was refused)
  // Where the map had the scan once the pose graph was optimised after it joined (matched_pose
  // with the graph off), and where the graph had it when the mission ended.
  Pose placed_pose;
  Pose final_pose;
  Pose prior_pose;  // the reported pose carried into the map frame: where matching started
  std::optional<RegistrationResult> match;  // when the scan was matched against the map
  bool match_applied = false;               // whether placed_pose is the match's correction
  // How far the match's result was from the truth (relative to the first scan), applied or
  // not: a refused match that was right, or an applied one that was wrong, shows here.
  std::optional<double> match_error_m, match_error_deg;
  std::optional<Pose> match_proposed;  // where the match's result would put the scan
  // How far placed_pose is from the truth, relative to the first scan (which defines the map
  // frame): what a rescue crew reading the map would be misled by.
  double placed_error_m = 0;
  double placed_error_deg = 0;
  // The same for matched_pose (before the graph) and final_pose.
  double matched_error_m = 0, matched_error_deg = 0;
  double final_error_m = 0, final_error_deg = 0;
  // Whether the map held the scan when the mission ended (with the graph, only scans tied in by
  // a believed match are in it; the others wait, at the graph's estimate).
  bool final_in_map = true;
  std::string final_outside;  // why not in the map at the end (MissionPipeline::outside_reason)
  // The graph's work after this scan: pairs matched of those tried, the solve, and how far it
  // moved the scans already in the map.
  std::size_t pairs_tried = 0, pairs_matched = 0;
  std::size_t rematches_tried = 0, rematched = 0;  // earlier refused scans matched again
  double graph_ms = 0;                             // pairwise matches and the solve
  double solve_ms = 0;
  double corrected_max_m = 0;  // the largest move of any scan in this step's optimisation
  std::size_t corrected_scans = 0;
  double detected_m2 = 0;             // C ∪ M, the paper's detection area
  double completed_m2 = 0;            // C
  double coverage_pct = 0;            // reachable ground cells of the target region that are in C
  double path_m = 0;                  // driven so far, over the true ground
  double plan_ms = 0;                 // planning after this scan (0 after the last)
  std::vector<Candidate> candidates;  // ranked, as the operator would see them
  std::optional<std::size_t> chosen;  // the candidate driven to, if any
};

// The true pose `truth` in the map frame, which the first scan defines: the first scan's true
// pose maps onto where it was placed.
Pose true_in_map(const Pose& first_placed, const Pose& first_true, const Pose& truth);

// The placed pose's error against the truth relative to the first scan: translation (m) and
// rotation angle (degrees) of true_in_map(...)⁻¹ · placed.
struct PoseError {
  double metres = 0, degrees = 0;
};
PoseError placed_error(const Pose& first_placed, const Pose& first_true, const Pose& placed,
                       const Pose& truth);

// One edge of the pose graph at the end of the run, judged against the truth.
struct LoopEdge {
  std::size_t from = 0, to = 0;       // scans, 0-based
  std::string origin;                 // ScanGraph::edge_origin
  double error_m = 0, error_deg = 0;  // the measured relative pose against the true one
  double whitened = 0;                // PoseGraph::whitened_error at the end
};

// How far apart the surfaces of overlapping scans in the map are (issue 17's target: median
// ≤ 2 cm, the range noise being 1 cm): for every two scans in the map within `max_apart_m` of
// each other that share at least 500 points within 0.2 m, the median distance of one scan's
// points from the other's surface along its normal; `median_m` is the median over those pairs,
// `worst_pair_m` the largest. The same over the walls alone (`wall_*`, pairs sharing at least
// 100 wall points): on flat open ground two scans metres apart in x-y still share the floor.
struct SurfaceDistance {
  std::size_t pairs = 0;
  double median_m = 0, worst_pair_m = 0;
  std::size_t wall_pairs = 0;
  double wall_median_m = 0, worst_wall_pair_m = 0;
};
SurfaceDistance surface_distance(const MissionPipeline& mission, double max_apart_m = 45.0);

struct LoopResult {
  std::vector<LoopStep> steps;
  std::vector<LoopEdge> edges;      // empty with the graph off
  SurfaceDistance surface;          // the map at the end
  std::size_t reachable_cells = 0;  // the coverage denominator
  std::optional<int> scans_to_95pct;
  std::optional<double> path_to_95pct_m;
  std::string stopped_because;
};

// The simulated robot's name in the scan graph (its track).
inline const std::string kLoopTrack = "robot";

// The paper's procedure (§3: scan, map, movable region, plan, move, repeat) on a simulated
// world: scans at the true pose, placed in the map at the reported one; the robot drives to
// the best-ranked candidate it can really reach (an operator approving the top suggestion).
// `on_step` sees each step with the mission (its map, graph and matcher) as it stands after
// that scan.
LoopResult run_closed_loop(
    const World& world, const ClosedLoopConfig& config,
    const std::function<void(const LoopStep&, const MissionPipeline&)>& on_step = {});

}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string_view>
#include <vector>

#include "scanplan/geometry/target_region.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"
#include "scanplan/planning/gain_memo.hpp"
#include "scanplan/planning/registrability.hpp"
#include "scanplan/planning/visibility.hpp"

namespace scanplan {

// How the next scan point is chosen among the movable cells (paper §3.4 and beyond it).
enum class PlannerPolicy {
  kPaper,            // hill climbing on F from seeded random starts (paper §3.4)
  kExhaustive,       // F at every movable cell (or every lattice_m), the best wins
  kTravel,           // F traded against the drive there (paper §5 future work)
  kNearestFrontier,  // the nearest movable cell next to unscanned cells (Yamauchi's frontiers)
  kRandom,           // a seeded random movable cell where a scan gains something
};

// "paper", "exhaustive", "travel", "nearest-frontier", "random"; nothing for other names.
std::optional<PlannerPolicy> parse_policy(std::string_view name);
std::string_view policy_name(PlannerPolicy policy);

struct PlannerConfig {
  PlannerPolicy policy = PlannerPolicy::kPaper;
  double alpha = 0.5;  // paper Eq. 1 weight α (§3.4); §3.5 uses 0.5
  std::uint64_t seed = 1;
  // Paper §3.4: hill climbing "from several randomized initial locations".
  int hill_climb_starts = 8;
  // Hill climbing moves to the best of the 8 neighbours this far away while that improves F,
  // then halves the move down to one cell: the long moves cross F's small local ripples
  // (cell-sized noise of the discrete beams) that stop a one-cell climb early.
  double hill_climb_step_m = 4.0;
  // The starts are the best hill_climb_starts of about this many movable cells on a lattice
  // at a random offset (0: hill_climb_starts random cells, as the paper has it). Over 20
  // steps on the campus this brings the climbs within 0.6% of the exhaustive optimum on
  // average, against 6% from purely random starts (docs/benchmarks.md).
  int hill_climb_samples = 1024;
  // The screening of those samples predicts each scan with rays this many times sparser in
  // azimuth (azimuth_step_deg and max_ray_spacing_m multiplied; 1: the climbs' own fan). It only
  // ranks where to start: every start, and every F a plan reports, is evaluated with the full
  // fan. Sparser rays miss a share of the far cells at every site alike, so the ranking of the
  // sample holds while each look costs about half (docs/benchmarks.md, issue 19).
  int screening_coarsening = 3;
  double lattice_m = 1.0;  // exhaustive: candidate spacing, in whole cells
  // exhaustive: ranks by F + completion_weight · area((U∪M_A)∩C_B), so that of two points
  // whose F differs by less than a few per cent (within the prediction's own error) the one
  // that completes more ground goes first.
  double completion_weight = 0.05;
  int max_candidates = 5;  // ranked list length
  // The operator's no-go zones (a collapse, a fire, a fuel spill): no candidate lies in one and
  // no drive to a candidate crosses one. What lies in them is still mapped from outside.
  std::vector<TargetRegion> no_go;
  // travel: score = F − travel_cost_per_m · F_best · max(0, drive − travel_free_m), where
  // F_best is the best F of the policy's first look over the region (its lattice sample).
  // Scans within travel_free_m of driving compete on F alone, as in `paper`; what the trade
  // removes is the long drive across the site to a scan hardly better than one nearby. A metre
  // beyond that costs a fixed share of what the best scan would gain, so the trade keeps its
  // balance as the gains shrink over a mission (an absolute cost in m²/m that suits the first
  // scans pins the robot to crumbs near the end). Chosen on the campus, 10 seeds to 95%
  // coverage (docs/benchmarks.md): as many scans as `paper` (37.4) on 0.67× its path; a cost
  // from the first metre (free 0) saved a little more path for about half a scan more.
  double travel_cost_per_m = 0.005;
  double travel_free_m = 80.0;
  // Candidates in the ranked list lie at least this far apart, so that the operator chooses
  // among different places rather than neighbouring cells of one.
  double candidate_separation_m = 5.0;
  // Several robots on one map (PlanInput::claimed): no candidate lies this close to where
  // another robot is going to scan, so two robots are never sent to the same spot. Half the
  // paper's 20 m completed radius (§3.3): nearer than that, two scans mostly complete the same
  // ground, which the claimed gains already discount.
  double claim_separation_m = 10.0;
  // ...and none this close to where another robot stands (PlanInput::occupied): a robot's
  // footprint with a margin.
  double robot_clearance_m = 2.0;
  // ...and none this close to a point the robot refused (PlanInput::refused): the same place, as
  // the ranked list's candidate_separation_m counts places.
  double refused_clearance_m = 5.0;
  // Several robots (plan_fleet): best candidates scoring within this share of the highest
  // count as equally good, and the robot with the shortest drive to its own takes it.
  double fleet_tie_share = 0.02;
  // A scan that would gain less than this (F, in m²) is not worth making.
  double min_gain_m2 = 1.0;
  // Candidates and paths keep to cells whose centre is in the target region (paths from a robot
  // standing outside it may cross any cell: travel_map).
  bool stay_in_target = true;
  int threads = 0;  // OpenMP threads for the evaluations; 0: the OpenMP default
  VisibilityConfig visibility;
  RegionConfig regions;
  MovableConfig movable;
  // With an anchored map (PlanInput::anchored) each candidate carries a forecast of the scan
  // matcher's outcome, and the paper, exhaustive and travel policies scale F down where it is
  // forecast to fail, so the next scan stays registrable.
  RegistrabilityConfig registrability;
};

struct Candidate {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // x, y, floor z of the scan point B
  double f = 0;                                        // Eq. 1 value
  double gain_unscanned_m2 = 0;                        // area((U∩C_B) ∪ (U∩M_B))
  double gain_low_res_m2 = 0;                          // area(M_A∩C_B)
  double gain_completed_m2 = 0;  // area((U∪M_A)∩C_B): what the scan brings into C (not in F)
  double overlap_m2 = 0;         // area of the map so far seen from B (ScanGain::overlap_m2)
  // The forecast of the matcher's outcome there (ScanGain::registrability), when forecast.
  std::optional<Registrability> registrability;
  double travel_m = 0;                // path length over the movable region from the robot
  std::vector<Eigen::Vector2d> path;  // cell centres from the robot to B
  // What the policy ranked by: F (paper, random), F + completion_weight · gain_completed_m2
  // (exhaustive), F − travel_cost_per_m · F_best · max(0, travel_m − travel_free_m) (travel),
  // −travel_m (nearest-frontier).
  double score = 0;
};

struct PlanInput {
  const MlsMap& map;
  const TargetRegion& target;
  const std::vector<Eigen::Vector2d>& scan_points;  // where scans were taken (x, y)
  Eigen::Vector3d robot;                            // x, y, floor z
  // Where other robots on the same map are going to scan next (x, y, floor z): their approved
  // goals, or the best candidates of their own plans. Planning for several robots one after
  // another (a sequential greedy coordination, as in Burgard et al.'s coordinated
  // exploration), each robot's F counts what a scan at a claimed point is predicted to see as
  // already taken: U it would see becomes M or C, M it would see within the completed radius
  // becomes C, as segment_regions would have it after that scan. Null or empty: one robot.
  const std::vector<Eigen::Vector3d>* claimed = nullptr;
  // Where the other robots stand now (x, y, floor z): no candidate within robot_clearance_m.
  const std::vector<Eigen::Vector3d>* occupied = nullptr;
  // Points this robot refused to drive to (x, y): no candidate within refused_clearance_m, until
  // the map there changes (the caller forgets them then).
  const std::vector<Eigen::Vector2d>* refused = nullptr;
  // The part of `map` the scan matcher matches against (the anchored scans; MissionPipeline),
  // on the same cells: candidates are forecast against it (PlannerConfig::registrability).
  // Null: no forecast (matching off, or a tool with one map).
  const MlsMap* anchored = nullptr;
  // With odometry that drifts: how uncertain the robot's pose is now and grows as it drives;
  // candidates are forecast with the drive there (RegistrabilityConfig::reach_xy_m). Null: pose
  // sensors that do not drift.
  const DriveDrift* drift = nullptr;
  // Evaluations kept from this robot's previous plans, reused where the map they read has not
  // changed (GainMemo), and this plan's kept for the next. The plan is the same with or without.
  // Null: every evaluation made afresh.
  GainMemo* memo = nullptr;
};

struct Plan {
  std::vector<Candidate> ranked;  // best first
  RegionMap regions;              // the map's C/M/U segmentation (without the claims)
  MovableRegion movable;
  std::size_t evaluations = 0;  // F values the policy looked at
  std::size_t reused = 0;       // of them, taken from PlanInput::memo
  // The most a scan at any place the policy looked at would add (unscanned and low-resolution
  // area), whether or not the matcher is forecast to place it: the ranking puts such places
  // behind ones it can place, but while one is left the mission is not done (it becomes
  // placeable once scans nearer it are in the map).
  double best_gain_m2 = 0;
  double plan_ms = 0;
};

// The next scan point (paper §3, steps 3-4): segments C/M/U, floods the movable region from
// the robot, and ranks movable cells by the policy. `ranked` is empty when no cell is movable
// or no scan would gain min_gain_m2. Deterministic for a seed, whatever the thread count.
// Throws std::invalid_argument for a config out of range.
Plan plan_next_scan(const PlanInput& in, const PlannerConfig& cfg);

// F (Eq. 1) for a scan at `b` (x, y, floor z) against the current map and scan points; fills
// the gain fields and position of `detail` when given. For tests and tools; plan_next_scan
// evaluates many cells far faster.
double evaluate(const PlanInput& in, const PlannerConfig& cfg, const Eigen::Vector3d& b,
                Candidate* detail = nullptr);

}  // namespace scanplan

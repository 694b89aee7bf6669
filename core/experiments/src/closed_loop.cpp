#include "scanplan/experiments/closed_loop.hpp"

#include <chrono>
#include <optional>
#include <random>
#include <set>

#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/registration/alignment_quality.hpp"
#include "scanplan/sim/simulated_odometry.hpp"
#include "scanplan/sim/simulated_scanner.hpp"
#include "scanplan/sim/world_traversability.hpp"

namespace scanplan {
namespace {

// The coverage denominator: MLS cells of the target region holding ground the robot could
// reach from its start in the true world (DESIGN.md: coverage_pct), as cells of the map, whose
// frame (the first scan's placed pose) is `map_from_world` from the world's.
std::vector<CellIndex> reachable_ground_cells(const World& world, const WorldTraversability& trav,
                                              const WorldTraversability::Reach& reach,
                                              const MlsMap& map,
                                              const Eigen::Isometry3d& map_from_world) {
  std::set<std::pair<std::int32_t, std::int32_t>> cells;
  for (std::size_t c = 0; c < trav.cell_count(); ++c) {
    if (!reach.reachable(c)) continue;
    const Eigen::Vector2d p = trav.cell_center(c);
    if (!world.in_target_region(p.x(), p.y())) continue;
    const Eigen::Vector3d in_map = map_from_world * Eigen::Vector3d(p.x(), p.y(), 0);
    const CellIndex i = map.index_of(in_map.x(), in_map.y());
    cells.insert({i.x, i.y});
  }
  std::vector<CellIndex> out;
  out.reserve(cells.size());
  for (const auto& [x, y] : cells) out.push_back({x, y});
  return out;
}

// The share of `ground` the regions count as scan-completed, in per cent.
double coverage_pct(const RegionMap& regions, const std::vector<CellIndex>& ground) {
  std::size_t covered = 0;
  for (const CellIndex& c : ground) covered += regions.at(c) == Region::kCompleted;
  return ground.empty() ? 0.0
                        : 100.0 * static_cast<double>(covered) / static_cast<double>(ground.size());
}

// The operator approving the best suggestion the robot can really reach: the first ranked
// candidate reachable in the true world (the map was built from noisy poses, so a suggestion
// may not be drivable). The candidates are places on the map, and the robot goes to that place
// (`world_from_map`, the first scan's true pose against where it was placed), as a robot that
// navigates on the map does. Moves `truth` there and adds the drive to `path_m`.
std::optional<std::size_t> drive_to_best(const WorldTraversability& trav,
                                         const std::vector<Candidate>& ranked,
                                         const Eigen::Isometry3d& world_from_map, Pose& truth,
                                         double& path_m) {
  const auto reach = trav.reach_from(truth.x, truth.y, truth.z);
  for (std::size_t k = 0; k < ranked.size(); ++k) {
    const Eigen::Vector3d goal = world_from_map * ranked[k].position;
    const auto cell = trav.cell_of(goal.x(), goal.y());
    if (cell && reach.reachable(*cell)) {
      path_m += reach.distance_m[*cell];
      truth = trav.standing_pose(goal.x(), goal.y(), reach.z[*cell], truth.yaw);
      return k;
    }
  }
  return std::nullopt;
}

// The scan matched against the map and joined, the graph optimised: step's poses and match.
// `goal`, `driven_m`: where the robot was sent and the length of the path the planner gave it
// there (Placement).
void place(MissionPipeline& mission, const PointCloud& cloud, LoopStep& step,
           const std::optional<Eigen::Vector3d>& goal, double driven_m) {
  step.prior_pose = mission.prior(step.reported_pose, kLoopTrack);
  step.matched_pose = step.prior_pose;
  Placement where{step.reported_pose, step.prior_pose, false};
  where.track = kLoopTrack;
  where.goal = goal;
  where.driven_m = driven_m;
  if (const auto m = mission.place(cloud, step.reported_pose, kLoopTrack, driven_m)) {
    step.match = m->result;
    step.match_applied = m->applied;
    step.matched_pose = m->placed;
    step.match_proposed = m->proposed;
    where.placed = m->placed;
    where.matched = m->applied;
    where.information = m->information;
  }
  mission.add(cloud, where);
  step.placed_pose = mission.poses().back();
  if (const auto& c = mission.last_correction()) {
    step.pairs_tried = c->graph.pairs_tried;
    step.pairs_matched = c->graph.pairs_matched;
    step.rematches_tried = c->graph.rematches_tried;
    step.rematched = c->graph.rematched;
    step.graph_ms = c->graph.match_ms + c->graph.solve.time_ms;
    step.solve_ms = c->graph.solve.time_ms;
    step.corrected_max_m = c->max_moved_m;
    step.corrected_scans = c->moved.size();
  }
}

// The world's target region in the map frame.
TargetRegion target_in_map(const World& world, const Eigen::Isometry3d& map_from_world) {
  std::vector<Eigen::Vector2d> corners;
  const TargetRegion region = world.target_region();
  for (const Eigen::Vector2d& c : region.corners()) {
    corners.push_back((map_from_world * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>());
  }
  return TargetRegion::polygon(std::move(corners));
}

// How far the step's poses are from the truth, relative to the first scan.
void step_errors(const LoopStep& first, LoopStep& step) {
  const auto error = [&](const Pose& p, double& metres, double& degrees) {
    const PoseError e = placed_error(first.placed_pose, first.true_pose, p, step.true_pose);
    metres = e.metres;
    degrees = e.degrees;
  };
  error(step.placed_pose, step.placed_error_m, step.placed_error_deg);
  error(step.matched_pose, step.matched_error_m, step.matched_error_deg);
  if (step.match_proposed) {
    double m = 0, d = 0;
    error(*step.match_proposed, m, d);
    step.match_error_m = m;
    step.match_error_deg = d;
  }
}

}  // namespace

SurfaceDistance surface_distance(const MissionPipeline& mission, double max_apart_m) {
  // Thinned for speed: the target's surface from 0.1 m cubes (its normals from eight of them),
  // 0.2 m cubes of the other scan measured against it.
  constexpr double kTargetVoxelM = 0.1, kSourceVoxelM = 0.2;
  // Points farther than this from the other scan see what it did not: no overlap there.
  constexpr double kOverlapM = 0.2;
  constexpr std::size_t kMinOverlapPoints = 500;
  std::vector<std::size_t> in_map;
  for (std::size_t i = 0; i < mission.poses().size(); ++i) {
    if (mission.in_map(i)) in_map.push_back(i);
  }
  std::vector<PointCloud> target(mission.poses().size()), source(mission.poses().size());
  for (const std::size_t i : in_map) {
    const PointCloud at = mission.at_estimate(i);
    target[i] = voxel_downsample(at, kTargetVoxelM);
    source[i] = voxel_downsample(at, kSourceVoxelM);
  }
  constexpr std::size_t kMinWallPoints = 100;
  SurfaceDistance out;
  std::vector<double> medians, wall_medians;
  for (std::size_t a = 0; a < in_map.size(); ++a) {
    const Pose& pa = mission.poses()[in_map[a]];
    const AlignmentJudge judge(target[in_map[a]]);
    for (std::size_t b = a + 1; b < in_map.size(); ++b) {
      const Pose& pb = mission.poses()[in_map[b]];
      if (std::hypot(pa.x - pb.x, pa.y - pb.y) > max_apart_m) continue;
      const AlignmentQuality q = judge.evaluate(source[in_map[b]], Eigen::Isometry3d::Identity(),
                                                Dof::k4, kOverlapM, kOverlapM);
      if (q.inliers < kMinOverlapPoints) continue;
      medians.push_back(q.median_plane_distance_m);
      out.worst_pair_m = std::max(out.worst_pair_m, q.median_plane_distance_m);
      if (q.wall_inliers < kMinWallPoints) continue;
      wall_medians.push_back(q.median_wall_distance_m);
      out.worst_wall_pair_m = std::max(out.worst_wall_pair_m, q.median_wall_distance_m);
    }
  }
  const auto median = [](std::vector<double>& v) {
    const auto middle = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), middle, v.end());
    return *middle;
  };
  out.pairs = medians.size();
  if (!medians.empty()) out.median_m = median(medians);
  out.wall_pairs = wall_medians.size();
  if (!wall_medians.empty()) out.wall_median_m = median(wall_medians);
  return out;
}

namespace {

// Where the graph had each scan when the mission ended, against the truth.
void final_errors(const MissionPipeline& mission, LoopResult& result) {
  if (result.steps.empty()) return;
  const LoopStep& first = result.steps.front();
  for (std::size_t k = 0; k < result.steps.size(); ++k) {
    LoopStep& s = result.steps[k];
    s.final_pose = mission.poses().at(k);
    s.final_in_map = mission.in_map(k);
    s.final_outside = mission.outside_reason(k);
    if (k == 0) continue;
    const PoseError e = placed_error(first.placed_pose, first.true_pose, s.final_pose, s.true_pose);
    s.final_error_m = e.metres;
    s.final_error_deg = e.degrees;
  }
  const ScanGraph* graph = mission.graph();
  if (!graph) return;
  const auto truth = [&](std::size_t k) {
    return true_in_map(first.placed_pose, first.true_pose, result.steps.at(k).true_pose);
  };
  for (std::size_t i = 0; i < graph->graph().edges().size(); ++i) {
    const GraphEdge& e = graph->graph().edges()[i];
    const RelativePose t = relative_pose(truth(e.from), truth(e.to));
    result.edges.push_back({e.from, e.to, graph->edge_origin(i),
                            std::hypot(e.measured.x - t.x, e.measured.y - t.y, e.measured.z - t.z),
                            std::abs(rad2deg(std::remainder(e.measured.yaw - t.yaw, 2 * M_PI))),
                            graph->graph().whitened_error(i)});
  }
}

}  // namespace

Pose true_in_map(const Pose& first_placed, const Pose& first_true, const Pose& truth) {
  return Pose::from_isometry(first_placed.isometry() * first_true.isometry().inverse() *
                             truth.isometry());
}

PoseError placed_error(const Pose& first_placed, const Pose& first_true, const Pose& placed,
                       const Pose& truth) {
  const Eigen::Isometry3d e =
      true_in_map(first_placed, first_true, truth).isometry().inverse() * placed.isometry();
  return {e.translation().norm(), rad2deg(Eigen::AngleAxisd(e.linear()).angle())};
}

LoopResult run_closed_loop(
    const World& world, const ClosedLoopConfig& config,
    const std::function<void(const LoopStep&, const MissionPipeline&)>& on_step) {
  const RayCaster caster(world);
  const WorldTraversability trav(world, caster);
  Pose truth = trav.standing_pose(world.start.x, world.start.y, world.start.z, world.start.yaw);

  MissionConfig mission_config;
  mission_config.mapping = config.pipeline;
  mission_config.planner = config.planner;
  mission_config.matching = config.matching;
  mission_config.pose_noise = world.pose_noise;
  mission_config.graph = config.graph;
  mission_config.view_check = config.view_check;
  mission_config.mapping.sensor_height_m = world.scanner.mount_height_m;
  MissionPipeline mission(mission_config);
  const MappingPipeline& pipeline = mission.mapping();
  const auto start_reach = trav.reach_from(truth.x, truth.y, truth.z);
  // The map's frame is the first scan's placed (reported) pose, not the world's: the target
  // region and the ground to cover are carried into it once that scan is in.
  Eigen::Isometry3d world_from_map = Eigen::Isometry3d::Identity();
  std::vector<CellIndex> ground;

  LoopResult result;
  SimulatedOdometry odometry(world.pose_noise, truth, config.seed);
  double path_m = 0;
  std::optional<Eigen::Vector3d> goal;  // where the robot was last sent, on the map
  double goal_travel_m = 0;             // the planned path there
  for (int scan = 1; scan <= config.max_scans; ++scan) {
    LoopStep step;
    step.scan = scan;
    step.true_pose = truth;
    const PointCloud cloud = simulate_scan(caster, world.scanner, truth,
                                           config.seed * 7919 + static_cast<std::uint64_t>(scan));
    step.reported_pose = odometry.reported();
    if (scan == 1) {
      world_from_map = truth.isometry() * step.reported_pose.isometry().inverse();
      const Eigen::Isometry3d map_from_world = world_from_map.inverse();
      mission.set_target(target_in_map(world, map_from_world));
      ground = reachable_ground_cells(world, trav, start_reach, pipeline.map(), map_from_world);
      result.reachable_cells = ground.size();
    }
    place(mission, cloud, step, goal, goal_travel_m);
    if (!result.steps.empty()) step_errors(result.steps.front(), step);
    const RegionMap& regions = *pipeline.regions();
    step.detected_m2 = regions.detected_m2();
    step.completed_m2 = regions.completed_m2();
    step.coverage_pct = coverage_pct(regions, ground);
    step.path_m = path_m;
    if (!result.scans_to_95pct && step.coverage_pct >= 95.0) {
      result.scans_to_95pct = scan;
      result.path_to_95pct_m = path_m;
    }

    const bool last = scan == config.max_scans || step.coverage_pct >= config.stop_at_coverage_pct;
    if (!last) {
      const auto t0 = std::chrono::steady_clock::now();
      // Where the map knows the robot to be: its latest scan, or, when that one could not be
      // placed (it waits outside the map, perhaps metres off), the latest the map holds.
      const Pose& at = mission.in_map(mission.poses().size() - 1) ? step.placed_pose
                                                                  : pipeline.scan_poses().back();
      const Plan plan = mission.plan_from(
          {at.x, at.y, at.z}, config.planner.seed * 1000003u + static_cast<std::uint64_t>(scan),
          kLoopTrack);
      step.plan_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      step.candidates = plan.ranked;
      const double before = path_m;
      step.chosen = drive_to_best(trav, plan.ranked, world_from_map, truth, path_m);
      if (step.chosen) {
        odometry.moved(truth, path_m - before);
        goal = plan.ranked[*step.chosen].position;
        goal_travel_m = plan.ranked[*step.chosen].travel_m;
      }
    }
    if (on_step) on_step(step, mission);
    result.steps.push_back(std::move(step));
    const LoopStep& done = result.steps.back();
    if (done.coverage_pct >= config.stop_at_coverage_pct) {
      result.stopped_because = "coverage reached";
      break;
    }
    if (!last && !done.chosen) {
      result.stopped_because = done.candidates.empty() ? "the planner found nothing left to scan"
                                                       : "no suggested point is reachable";
      break;
    }
    if (last) result.stopped_because = "scan limit reached";
  }
  final_errors(mission, result);
  result.surface = surface_distance(mission);
  return result;
}

}  // namespace scanplan

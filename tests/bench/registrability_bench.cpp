// The planner's forecast of the scan matcher (RegistrabilityField, issue 15) against what the
// matcher then does. The campus loop runs as `simulate` runs it (drifting odometry, matching and
// the graph on); after each scan, at the best-ranked candidates the robot could drive to, a scan
// is simulated, reported with the drift of the drive there, and matched to the map as it stands
// (MissionPipeline::place, which changes nothing). Each candidate is forecast by every variant
// on the same map: the baseline (every wall counts from anywhere, a wall's direction from the
// cells within 2 of it: the forecast before 2026-12-07), RegistrabilityConfig::sided_walls
// alone, with wall_line_radius_cells too, and with corner_faces too (the planner's). A candidate
// is forecast registrable when the forecast keeps its whole score (factor 1); a match is right
// when applied within 10 cm / 0.3° of the truth. Prints one JSON line: per variant the confusion
// counts and how well pose_fixing and the score share rank right matches above failed ones (AUC).
// Usage: registrability_bench [SEEDS=3] [SCANS=25] [PER_STEP=6] [WORLD.json] [SAMPLES.csv]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "scanplan/experiments/closed_loop.hpp"
#include "scanplan/graph/relative_pose.hpp"
#include "scanplan/planning/scan_planner.hpp"
#include "scanplan/sim/simulated_scanner.hpp"
#include "scanplan/sim/world_traversability.hpp"

namespace {

using namespace scanplan;

struct Variant {
  const char* name;
  bool sided_walls;
  int wall_line_radius_cells;
  bool corner_faces;
};
constexpr Variant kVariants[] = {{"baseline", false, 0, false},
                                 {"sided_walls", true, 0, false},
                                 {"wall_lines", true, 6, false},
                                 {"corner_faces", true, 6, true}};
constexpr int kVariantCount = sizeof kVariants / sizeof kVariants[0];

struct Sample {
  int seed = 0, scan = 0, rank = 0;
  double x = 0, y = 0, travel_m = 0;
  bool applied = false, right = false;
  double error_m = 0, weakest_constraint = 0, inlier_ratio = 0;
  Registrability forecast[kVariantCount];
};

// Area under the ROC curve of `score` for telling right matches (positives) from the others:
// the chance that a right one scores above a failed one (ties count half).
double auc(const std::vector<Sample>& samples, double (*score)(const Registrability&), int v) {
  double above = 0, pairs = 0;
  for (const Sample& p : samples) {
    if (!p.right) continue;
    for (const Sample& n : samples) {
      if (n.right) continue;
      const double a = score(p.forecast[v]), b = score(n.forecast[v]);
      above += a > b ? 1.0 : a == b ? 0.5 : 0.0;
      pairs += 1;
    }
  }
  return pairs > 0 ? above / pairs : 0.0;
}

double fixing(const Registrability& r) {
  return r.pose_fixing;
}
double factor(const Registrability& r) {
  return r.factor;
}

}  // namespace

int main(int argc, char** argv) {
  const int seeds = argc > 1 ? std::atoi(argv[1]) : 3;
  const int scans = argc > 2 ? std::atoi(argv[2]) : 25;
  const int per_step = argc > 3 ? std::atoi(argv[3]) : 6;
  const std::string world_file =
      argc > 4 ? argv[4] : std::string(SCANPLAN_SOURCE_DIR) + "/samples/worlds/campus.json";
  const std::string samples_csv = argc > 5 ? argv[5] : "";
  const World world = load_world(world_file);
  const RayCaster caster(world);
  const WorldTraversability trav(world, caster);
  const PoseNoise& noise = world.pose_noise;

  std::vector<Sample> samples;
  for (int seed = 1; seed <= seeds; ++seed) {
    ClosedLoopConfig config;  // as `simulate` runs it
    config.planner.seed = static_cast<std::uint64_t>(seed);
    config.seed = static_cast<std::uint64_t>(seed);
    config.max_scans = scans;
    std::mt19937_64 rng(static_cast<std::uint64_t>(seed) * 104729u);
    Eigen::Isometry3d world_from_map = Eigen::Isometry3d::Identity();
    Pose first_placed, first_true;
    run_closed_loop(world, config, [&](const LoopStep& step, const MissionPipeline& mission) {
      if (step.scan == 1) {
        world_from_map = step.true_pose.isometry() * step.reported_pose.isometry().inverse();
        first_placed = step.placed_pose;
        first_true = step.true_pose;
      }
      const MappingPipeline& mapping = mission.mapping();
      if (step.candidates.empty() || !mapping.target()) return;
      const std::vector<Eigen::Vector2d> points = mapping.scan_points();
      const Pose& at = mission.in_map(mission.poses().size() - 1) ? step.placed_pose
                                                                  : mapping.scan_poses().back();
      PlanInput in{mapping.map(), *mapping.target(), points, {at.x, at.y, at.z}};
      in.anchored = mission.anchored_map();
      const std::optional<DriveDrift> drift = mission.drift_of(kLoopTrack);
      if (drift) in.drift = &*drift;
      const auto reach = trav.reach_from(step.true_pose.x, step.true_pose.y, step.true_pose.z);
      int taken = 0;
      for (std::size_t k = 0; k < step.candidates.size() && taken < per_step; ++k) {
        const Candidate& c = step.candidates[k];
        const Eigen::Vector3d goal = world_from_map * c.position;
        const auto cell = trav.cell_of(goal.x(), goal.y());
        if (!cell || !reach.reachable(*cell)) continue;
        ++taken;
        const double driven = reach.distance_m[*cell];
        const Pose truth =
            trav.standing_pose(goal.x(), goal.y(), reach.z[*cell], step.true_pose.yaw);
        const PointCloud cloud =
            simulate_scan(caster, world.scanner, truth,
                          static_cast<std::uint64_t>(seed) * 7919u +
                              1000u * static_cast<std::uint64_t>(step.scan) + k);
        // The drive there as the robot's odometry reports it (PoseNoise's drift model).
        RelativePose move = relative_pose(step.true_pose, truth);
        std::normal_distribution<double> unit(0.0, 1.0);
        move.x += noise.xy_drift_fraction * driven * unit(rng);
        move.y += noise.xy_drift_fraction * driven * unit(rng);
        move.z += noise.z_drift_fraction * driven * unit(rng);
        move.yaw += deg2rad(noise.yaw_drift_deg_per_10m * driven / 10) * unit(rng);
        const Pose reported = compose(step.reported_pose, move, truth.roll, truth.pitch);
        const std::optional<MapMatch> m = mission.place(cloud, reported, kLoopTrack, driven);
        if (!m) continue;
        Sample s;
        s.seed = seed;
        s.scan = step.scan;
        s.rank = static_cast<int>(k);
        s.x = c.position.x();
        s.y = c.position.y();
        s.travel_m = driven;
        s.applied = m->applied;
        const PoseError e = placed_error(first_placed, first_true, m->proposed, truth);
        s.error_m = e.metres;
        s.right = m->applied && e.metres <= 0.10 && e.degrees <= 0.3;
        s.weakest_constraint = m->result.weakest_constraint;
        s.inlier_ratio = m->result.inlier_ratio;
        for (int v = 0; v < kVariantCount; ++v) {
          PlannerConfig planner = mission.planner_config();
          planner.registrability.sided_walls = kVariants[v].sided_walls;
          planner.registrability.wall_line_radius_cells = kVariants[v].wall_line_radius_cells;
          planner.registrability.corner_faces = kVariants[v].corner_faces;
          Candidate detail;
          evaluate(in, planner, c.position, &detail);
          if (detail.registrability) s.forecast[v] = *detail.registrability;
        }
        samples.push_back(s);
      }
    });
  }

  nlohmann::json out = {{"bench", "registrability_forecast"},
                        {"world", world.name},
                        {"seeds", seeds},
                        {"scans", scans},
                        {"per_step", per_step}};
  std::size_t right = 0, refused = 0;
  for (const Sample& s : samples) {
    right += s.right;
    refused += !s.applied;
  }
  out["samples"] = samples.size();
  out["matches_right"] = right;
  out["matches_refused"] = refused;
  out["matches_wrong"] = samples.size() - right - refused;
  for (int v = 0; v < kVariantCount; ++v) {
    // Forecast registrable (factor 1) against the match's outcome.
    std::size_t tp = 0, fp = 0, tn = 0, fn = 0;
    for (const Sample& s : samples) {
      const bool ok = s.forecast[v].factor >= 1.0;
      tp += ok && s.right;
      fp += ok && !s.right;
      tn += !ok && !s.right;
      fn += !ok && s.right;
    }
    out["variants"][kVariants[v].name] = {
        {"forecast_registrable_right", tp},           {"forecast_registrable_failed", fp},
        {"forecast_unregistrable_failed", tn},        {"forecast_unregistrable_right", fn},
        {"auc_pose_fixing", auc(samples, fixing, v)}, {"auc_factor", auc(samples, factor, v)}};
  }
  if (!samples_csv.empty()) {
    std::ofstream csv(samples_csv);
    csv << "seed,scan,rank,x,y,travel_m,applied,right,error_m,weakest_constraint,inlier_ratio";
    for (const Variant& v : kVariants) {
      csv << "," << v.name << "_overlap," << v.name << "_fixing," << v.name << "_factor";
    }
    csv << "\n";
    for (const Sample& s : samples) {
      csv << s.seed << "," << s.scan << "," << s.rank << "," << s.x << "," << s.y << ","
          << s.travel_m << "," << s.applied << "," << s.right << "," << s.error_m << ","
          << s.weakest_constraint << "," << s.inlier_ratio;
      for (const Registrability& r : s.forecast) {
        csv << "," << r.overlap_share << "," << r.pose_fixing << "," << r.factor;
      }
      csv << "\n";
    }
  }
  std::cout << out.dump() << std::endl;
  return 0;
}

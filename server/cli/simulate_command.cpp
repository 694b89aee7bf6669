#include "simulate_command.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <vector>

#include "scanplan/experiments/closed_loop.hpp"
#include "scanplan/experiments/coverage_chart.hpp"
#include "scanplan/planning/plan_view.hpp"

namespace scanplan::cli {
namespace {

struct SimulateArgs {
  std::string world, policy = "paper", out;
  double alpha = 0.5;
  int max_scans = 13;
  std::uint64_t seed = 1;
  std::string match = "on";
  std::string registrability = "on";
  std::string odometry;  // empty: the world file's
  std::string graph = "on";
  RegistrabilityConfig forecast;
  std::string view_check = "on";
  ViewCheckConfig view;
};

nlohmann::json optional_json(const auto& v) {
  return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
}

ClosedLoopConfig config_of(const SimulateArgs& a) {
  const auto policy = parse_policy(a.policy);
  if (!policy) {
    throw std::runtime_error(
        "--policy must be paper, exhaustive, travel, nearest-frontier or random");
  }
  if (a.alpha < 0 || a.alpha > 1) throw std::runtime_error("--alpha must be within 0..1");
  if (a.max_scans < 1) throw std::runtime_error("--max-scans must be at least 1");
  ClosedLoopConfig config;
  config.planner.policy = *policy;
  config.planner.alpha = a.alpha;
  config.planner.seed = a.seed;
  config.max_scans = a.max_scans;
  config.seed = a.seed;
  if (a.match == "off") config.matching.reset();
  if (a.graph == "off") config.graph.reset();
  config.planner.registrability = a.forecast;
  config.planner.registrability.enabled = a.registrability == "on";
  config.view_check = a.view;
  config.view_check.enabled = a.view_check == "on";
  return config;
}

// coverage.png: coverage and detected area against scans.
void write_chart(const LoopResult& r, const std::string& policy,
                 const std::filesystem::path& file) {
  ChartSeries coverage{policy, cv::Scalar(180, 100, 30), {{}}}, detected = coverage;
  for (const auto& s : r.steps) {
    coverage.runs[0].push_back(s.coverage_pct);
    detected.runs[0].push_back(s.detected_m2);
  }
  ChartStyle coverage_style, detected_style;
  coverage_style.title = "scan-completed reachable ground";
  coverage_style.y_label = "coverage (%)";
  coverage_style.references = {{95, "95 %"}};
  detected_style.title = "detected area (C + M)";
  detected_style.y_label = "area (m2)";
  cv::Mat chart;
  cv::hconcat(render_coverage_chart({coverage}, coverage_style),
              render_coverage_chart({detected}, detected_style), chart);
  cv::imwrite(file.string(), chart);
}

nlohmann::json pose_json(const Pose& p) {
  return {{"x", p.x}, {"y", p.y}, {"z", p.z}, {"yaw_deg", rad2deg(p.yaw)}};
}

// What the plan that sent the robot to a scan forecast of its match (Candidate::registrability).
nlohmann::json forecast_json(const LoopStep* previous) {
  if (!previous || !previous->chosen) return nullptr;
  const std::optional<Registrability>& r =
      previous->candidates.at(*previous->chosen).registrability;
  if (!r) return nullptr;
  nlohmann::json out = {{"overlap_share", r->overlap_share},
                        {"pose_fixing", r->pose_fixing},
                        {"reach", r->reach},
                        {"factor", r->factor}};
  if (r->predicted_constraint) out["predicted_constraint"] = *r->predicted_constraint;
  return out;
}

// One scan as summary.json lists it (DESIGN.md "CLI"): where the robot said it was, where the
// map put it and where it really was, all in the map frame (the first scan's), and the match.
nlohmann::json scan_json(const LoopStep& s, const LoopStep& first, const LoopStep* previous) {
  nlohmann::json match = nullptr;
  if (s.match) {
    match = {{"applied", s.match_applied},
             {"converged", s.match->converged},
             {"reason", s.match->message},
             {"method", s.match->method},
             {"time_ms", s.match->time_ms},
             {"inlier_ratio", s.match->inlier_ratio},
             {"weakest_constraint", s.match->weakest_constraint}};
    // The result's own error, applied or not: a right match refused, or a wrong one applied.
    if (s.match_error_m) {
      match["error_m"] = *s.match_error_m;
      match["error_deg"] = *s.match_error_deg;
    }
    if (s.match_proposed) match["proposed"] = pose_json(*s.match_proposed);
    match["prior"] = pose_json(s.prior_pose);
  }
  // "placed" is where the map has the scan at the end (the graph's last estimate); "matched"
  // where matching alone put it, "joined" where the map had it right after it came.
  return {{"scan", s.scan},
          {"reported", pose_json(s.reported_pose)},
          {"matched", pose_json(s.matched_pose)},
          {"joined", pose_json(s.placed_pose)},
          {"placed", pose_json(s.final_pose)},
          {"in_map", s.final_in_map},
          {"outside", s.final_in_map ? nlohmann::json(nullptr) : nlohmann::json(s.final_outside)},
          {"true", pose_json(true_in_map(first.placed_pose, first.true_pose, s.true_pose))},
          {"placed_error_m", s.final_error_m},
          {"placed_error_deg", s.final_error_deg},
          {"matched_error_m", s.matched_error_m},
          {"matched_error_deg", s.matched_error_deg},
          {"joined_error_m", s.placed_error_m},
          {"joined_error_deg", s.placed_error_deg},
          {"match", match},
          {"graph",
           {{"pairs_tried", s.pairs_tried},
            {"pairs_matched", s.pairs_matched},
            {"rematches_tried", s.rematches_tried},
            {"rematched", s.rematched},
            {"ms", s.graph_ms},
            {"solve_ms", s.solve_ms},
            {"corrected_scans", s.corrected_scans},
            {"corrected_max_m", s.corrected_max_m}}},
          {"forecast", forecast_json(previous)}};
}

// How the map's poses came out: matches tried and applied, and the placed error against the
// truth relative to the first scan (median and worst over the scans after it), at the end and
// from matching alone.
nlohmann::json accuracy_of(const LoopResult& r) {
  std::vector<double> metres, degrees, matched_m, matched_deg, solve_ms, in_map_m;
  int tried = 0, applied = 0;
  for (std::size_t k = 1; k < r.steps.size(); ++k) {
    const LoopStep& s = r.steps[k];
    metres.push_back(s.final_error_m);
    degrees.push_back(s.final_error_deg);
    matched_m.push_back(s.matched_error_m);
    matched_deg.push_back(s.matched_error_deg);
    solve_ms.push_back(s.solve_ms);
    if (s.final_in_map) in_map_m.push_back(s.final_error_m);
    tried += s.match.has_value();
    applied += s.match_applied;
  }
  const auto median = [](std::vector<double> v) -> nlohmann::json {
    if (v.empty()) return nullptr;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  };
  const auto worst = [](const std::vector<double>& v) -> nlohmann::json {
    if (v.empty()) return nullptr;
    return *std::max_element(v.begin(), v.end());
  };
  return {
      {"matches_tried", tried},
      {"matches_applied", applied},
      {"placed_error_median_m", median(metres)},
      {"placed_error_median_deg", median(degrees)},
      {"placed_error_max_m", worst(metres)},
      {"placed_error_max_deg", worst(degrees)},
      {"matched_error_median_m", median(matched_m)},
      {"matched_error_median_deg", median(matched_deg)},
      {"matched_error_max_m", worst(matched_m)},
      {"matched_error_max_deg", worst(matched_deg)},
      {"scans_in_map", in_map_m.size() + 1},
      {"in_map_error_median_m", median(in_map_m)},
      {"in_map_error_max_m", worst(in_map_m)},
      {"solve_ms_median", median(solve_ms)},
      {"solve_ms_max", worst(solve_ms)},
      // How far apart overlapping scans' surfaces are in the final map (SurfaceDistance).
      {"surface_pairs", r.surface.pairs},
      {"surface_distance_median_m", r.surface.pairs ? nlohmann::json(r.surface.median_m) : nullptr},
      {"surface_distance_worst_pair_m",
       r.surface.pairs ? nlohmann::json(r.surface.worst_pair_m) : nullptr},
      {"wall_pairs", r.surface.wall_pairs},
      {"wall_distance_median_m",
       r.surface.wall_pairs ? nlohmann::json(r.surface.wall_median_m) : nullptr},
      {"wall_distance_worst_pair_m",
       r.surface.wall_pairs ? nlohmann::json(r.surface.worst_wall_pair_m) : nullptr}};
}

// The pose graph's edges against the truth: which kinds of relation go wrong, and whether the
// robust loss set the wrong ones aside (a large whitened error).
nlohmann::json edges_json(const LoopResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const LoopEdge& e : r.edges) {
    out.push_back({{"from", e.from + 1},
                   {"to", e.to + 1},
                   {"origin", e.origin},
                   {"error_m", e.error_m},
                   {"error_deg", e.error_deg},
                   {"whitened", e.whitened}});
  }
  return out;
}

nlohmann::json summary_of(const SimulateArgs& a, const World& world, const ClosedLoopConfig& config,
                          const LoopResult& r) {
  double plan_ms = 0;
  int plans = 0;
  for (const auto& s : r.steps) {
    if (s.plan_ms > 0) plan_ms += s.plan_ms, ++plans;
  }
  const LoopStep& last = r.steps.back();
  // Where each scan was really taken (x, y, z, yaw_deg): to take the same scans again, e.g.
  // with `scanplan scan` for a server benchmark.
  nlohmann::json true_poses = nlohmann::json::array(), scans = nlohmann::json::array();
  for (std::size_t k = 0; k < r.steps.size(); ++k) {
    const LoopStep& s = r.steps[k];
    true_poses.push_back({s.true_pose.x, s.true_pose.y, s.true_pose.z, rad2deg(s.true_pose.yaw)});
    scans.push_back(scan_json(s, r.steps.front(), k > 0 ? &r.steps[k - 1] : nullptr));
  }
  const double cell_m = config.pipeline.mls.cell_m;
  return {{"world", world.name},
          {"policy", a.policy},
          {"alpha", a.alpha},
          {"seed", a.seed},
          {"match", a.match},
          {"graph", a.graph},
          {"odometry", odometry_model_name(world.pose_noise.model)},
          {"registrability", a.registrability},
          {"view_check", a.view_check},
          {"scans", scans},
          {"detected_m2", last.detected_m2},
          {"completed_m2", last.completed_m2},
          {"coverage_pct", last.coverage_pct},
          {"path_m", last.path_m},
          {"reachable_ground_m2", static_cast<double>(r.reachable_cells) * cell_m * cell_m},
          {"scans_to_95pct", optional_json(r.scans_to_95pct)},
          {"path_to_95pct_m", optional_json(r.path_to_95pct_m)},
          {"mean_plan_ms", plans ? plan_ms / plans : 0.0},
          {"stopped", r.stopped_because},
          {"accuracy", accuracy_of(r)},
          {"true_poses", true_poses},
          {"edges", edges_json(r)},
          {"out", a.out}};
}

void run_simulate(const SimulateArgs& a) {
  const ClosedLoopConfig config = config_of(a);
  World world = load_world(a.world);
  if (!a.odometry.empty()) world.pose_noise.model = *parse_odometry_model(a.odometry);
  const std::filesystem::path out(a.out);
  std::filesystem::create_directories(out);

  std::ofstream csv(out / "coverage.csv");
  if (!csv) throw std::runtime_error("cannot write " + (out / "coverage.csv").string());
  csv << "scan,x,y,detected_m2,completed_m2,coverage_pct,path_m,plan_ms,placed_error_m,"
         "placed_error_deg,matched_error_m,matched_error_deg\n";
  const auto on_step = [&](const LoopStep& s, const MissionPipeline& mission) {
    const MappingPipeline& pipeline = mission.mapping();
    char row[256];
    std::snprintf(row, sizeof row, "%d,%.3f,%.3f,%.1f,%.1f,%.2f,%.2f,%.1f,%.4f,%.3f,%.4f,%.3f\n",
                  s.scan, s.true_pose.x, s.true_pose.y, s.detected_m2, s.completed_m2,
                  s.coverage_pct, s.path_m, s.plan_ms, s.placed_error_m, s.placed_error_deg,
                  s.matched_error_m, s.matched_error_deg);
    csv << row << std::flush;
    cv::Mat img = render_regions(*pipeline.regions(), &*pipeline.movable(), pipeline.scan_points());
    draw_plan(img, *pipeline.regions(), s.candidates, s.chosen);
    char title[200];
    std::snprintf(title, sizeof title,
                  "%s, %s policy, seed %llu: scan %d, %.1f %% covered, %.0f m driven",
                  world.name.c_str(), a.policy.c_str(), static_cast<unsigned long long>(a.seed),
                  s.scan, s.coverage_pct, s.path_m);
    img = captioned_regions(img, *pipeline.regions(), title);
    char name[32];
    std::snprintf(name, sizeof name, "step_%02d.png", s.scan);
    cv::imwrite((out / name).string(), img);
    std::cerr << "scan " << s.scan << ": detected " << s.detected_m2 << " m², coverage "
              << s.coverage_pct << " %, plan " << s.plan_ms << " ms";
    if (s.match) {
      std::cerr << ", match " << (s.match_applied ? "applied" : "not applied") << ", placed "
                << s.placed_error_m << " m / " << s.placed_error_deg << "° from the truth";
      if (s.pairs_tried) {
        std::cerr << ", graph: " << s.pairs_matched << "/" << s.pairs_tried << " pairs, "
                  << s.corrected_scans << " scans moved (up to " << s.corrected_max_m << " m)";
      }
    }
    std::cerr << "\n";
  };
  const LoopResult r = run_closed_loop(world, config, on_step);
  write_chart(r, a.policy, out / "coverage.png");
  const nlohmann::json summary = summary_of(a, world, config, r);
  std::ofstream(out / "summary.json") << summary.dump(2) << "\n";
  std::cout << summary.dump() << std::endl;
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand("simulate", "the scan-plan-move loop on a simulated world");
  cmd->add_option("--world", args->world, "world file (JSON)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--policy", args->policy, "paper|exhaustive|travel|nearest-frontier|random")
      ->capture_default_str();
  cmd->add_option("--alpha", args->alpha, "weight α of Eq. 1 (paper §3.4)")->capture_default_str();
  cmd->add_option("--max-scans", args->max_scans, "scans at most")->capture_default_str();
  cmd->add_option("--seed", args->seed, "seed for noise and the planner")->capture_default_str();
  cmd->add_option("--match", args->match, "scan matching of each scan against the map (on|off)")
      ->capture_default_str()
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--odometry", args->odometry,
                  "drift|absolute: how the reported pose goes wrong (default: the world file's "
                  "pose_noise.model, drift when it has none)")
      ->check(CLI::IsMember({"drift", "absolute"}));
  cmd->add_option("--graph", args->graph,
                  "the pose graph over the scans, optimised after each (on|off; needs --match on)")
      ->capture_default_str()
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--registrability", args->registrability,
                  "the planner scales down candidates the matcher is forecast to fail at (on|off)")
      ->capture_default_str()
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--min-overlap-share", args->forecast.min_overlap_share,
                  "registrability: the overlap share below which a candidate loses score")
      ->capture_default_str()
      ->check(CLI::Range(0.001, 1.0));
  cmd->add_option("--min-pose-fixing", args->forecast.min_pose_fixing,
                  "registrability: the pose fixing below which a candidate loses score")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--view-check", args->view_check,
                  "registrability: the best candidates checked once more against the map's own "
                  "points a scan there would see (on|off)")
      ->capture_default_str()
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_option("--view-min-constraint", args->view.min_constraint,
                  "view check: the predicted weakest constraint below which a candidate loses "
                  "score")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", args->out,
                  "output folder (coverage.csv, coverage.png, step_NN.png, summary.json)")
      ->required();
  cmd->callback([args] { run_simulate(*args); });
}

}  // namespace scanplan::cli

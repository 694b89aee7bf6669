#include "simulate_command.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

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
  nlohmann::json true_poses = nlohmann::json::array();
  for (const auto& s : r.steps) {
    true_poses.push_back({s.true_pose.x, s.true_pose.y, s.true_pose.z, rad2deg(s.true_pose.yaw)});
  }
  const double cell_m = config.pipeline.mls.cell_m;
  return {{"world", world.name},
          {"policy", a.policy},
          {"alpha", a.alpha},
          {"seed", a.seed},
          {"match", a.match},
          {"scans", r.steps.size()},
          {"detected_m2", last.detected_m2},
          {"completed_m2", last.completed_m2},
          {"coverage_pct", last.coverage_pct},
          {"path_m", last.path_m},
          {"reachable_ground_m2", static_cast<double>(r.reachable_cells) * cell_m * cell_m},
          {"scans_to_95pct", optional_json(r.scans_to_95pct)},
          {"path_to_95pct_m", optional_json(r.path_to_95pct_m)},
          {"mean_plan_ms", plans ? plan_ms / plans : 0.0},
          {"stopped", r.stopped_because},
          {"true_poses", true_poses},
          {"out", a.out}};
}

void run_simulate(const SimulateArgs& a) {
  const ClosedLoopConfig config = config_of(a);
  const World world = load_world(a.world);
  const std::filesystem::path out(a.out);
  std::filesystem::create_directories(out);

  std::ofstream csv(out / "coverage.csv");
  if (!csv) throw std::runtime_error("cannot write " + (out / "coverage.csv").string());
  csv << "scan,x,y,detected_m2,completed_m2,coverage_pct,path_m,plan_ms\n";
  const auto on_step = [&](const LoopStep& s, const MappingPipeline& pipeline) {
    char row[256];
    std::snprintf(row, sizeof row, "%d,%.3f,%.3f,%.1f,%.1f,%.2f,%.2f,%.1f\n", s.scan, s.true_pose.x,
                  s.true_pose.y, s.detected_m2, s.completed_m2, s.coverage_pct, s.path_m,
                  s.plan_ms);
    csv << row << std::flush;
    cv::Mat img = render_regions(*pipeline.regions(), &*pipeline.movable(), pipeline.scan_points());
    draw_plan(img, *pipeline.regions(), s.candidates, s.chosen);
    char name[32];
    std::snprintf(name, sizeof name, "step_%02d.png", s.scan);
    cv::imwrite((out / name).string(), img);
    std::cerr << "scan " << s.scan << ": detected " << s.detected_m2 << " m², coverage "
              << s.coverage_pct << " %, plan " << s.plan_ms << " ms\n";
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
  cmd->add_option("--out", args->out,
                  "output folder (coverage.csv, coverage.png, step_NN.png, summary.json)")
      ->required();
  cmd->callback([args] { run_simulate(*args); });
}

}  // namespace scanplan::cli

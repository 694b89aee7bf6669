// Scan-point planner on the campus (issue 5): one planning step per policy on the map after
// five scans, on 2 threads; the optimality gap of `paper` (hill climbing) against `exhaustive`
// over 20 planning steps of a closed loop; and how well the predicted view of a scan matches
// the cells the simulated scan then really adds. The baseline, run in the same process, is
// the paper's way of predicting a scan (§3.4: "a ray-tracing scan in 3-D virtual space"): every
// beam of the fan cast on its own through the MLS map, cell by cell, with the same model of
// unknown cells and the same gap filling, so the two must agree and only the cost differs.
// Prints one JSON line. Usage: planner_bench [WORLD.json] [STEPS]
//
// planner_bench --coverage SEEDS POLICIES [WORLD.json] [MAX_SCANS] [PLOT.png]: the closed loop
// (run_closed_loop) with each policy of the comma-separated list until 95% of the reachable
// ground is scan-completed (or MAX_SCANS, 60), SEEDS seeds each, poses exact and matching off
// so that only the planning differs; scans and path to 95% and the area detected after 13
// scans, mean and sd, and every run's curves. Prints one JSON line; PLOT.png charts coverage,
// detected area and path against scans. --travel-cost X / --travel-free M set the travel
// policy's trade.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <functional>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "scanplan/experiments/closed_loop.hpp"
#include "scanplan/experiments/coverage_chart.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/top_view.hpp"
#include "scanplan/planning/scan_planner.hpp"
#include "scanplan/planning/visibility.hpp"
#include "scanplan/sim/simulated_scanner.hpp"
#include "scanplan/sim/world_traversability.hpp"

namespace {

using Clock = std::chrono::steady_clock;
using namespace scanplan;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// CPU time of the whole process (all threads): on a shared machine the wall clock also counts
// the time other work held the cores.
double cpu_ms() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) / 1e6;
}

struct BeamReturn {
  double d, z;  // horizontal distance, height
};

// One beam from height sz along `dir` at slope t: walks the cells under it in 1/8-cell steps (a
// cell clipped by less is missed, as the sampling of a plain ray march would miss it) until its
// height inside a cell meets a patch. The return, when one is in range, and its cell.
std::optional<std::pair<BeamReturn, CellIndex>> cast_beam(const MlsMap& map,
                                                          const Eigen::Vector2d& o,
                                                          const Eigen::Vector2d& dir, double sz,
                                                          double t, double floor_z,
                                                          const VisibilityConfig& cfg) {
  const double cell = map.cell_m();
  double ground = floor_z;
  CellIndex last{INT32_MIN, INT32_MIN};
  for (double d = 0; d < cfg.max_range_m; d += cell / 8) {
    const Eigen::Vector2d p = o + d * dir;
    const CellIndex c = map.index_of(p.x(), p.y());
    if (c == last) continue;
    last = c;
    // The beam's heights across this cell: entry and exit along the ray.
    const Eigen::Vector2d lo_xy(c.x * cell, c.y * cell);
    const double d0 = d;
    double exit = 1e9;  // where the ray leaves the cell's square
    for (int axis = 0; axis < 2; ++axis) {
      if (std::abs(dir[axis]) < 1e-12) continue;
      const double bound = dir[axis] > 0 ? lo_xy[axis] + cell : lo_xy[axis];
      exit = std::min(exit, (bound - o[axis]) / dir[axis]);
    }
    const double d1 = std::max(d0, exit);
    const double za = sz + t * d0, zb = sz + t * d1;
    const double zlo = std::min(za, zb), zhi = std::max(za, zb);
    const MlsCell* mls = map.cell(c);
    std::vector<std::pair<double, double>> patches;
    const bool hanging = mls && mls->patches[0].min_z > ground + cfg.ground_max_jump_m;
    if (!mls || hanging) {
      if (cfg.unknown_as_ground) patches.emplace_back(-1e9, ground);
    } else {
      const auto& p0 = mls->patches[0];
      if (p0.extent() <= cfg.ground_max_extent_m &&
          std::abs(p0.max_z - ground) <= cfg.ground_max_jump_m) {
        ground = p0.max_z;
      }
    }
    if (mls) {
      for (const auto& patch : *mls) patches.emplace_back(patch.min_z, patch.max_z);
    }
    if (!hanging && !patches.empty()) patches[0].first = -1e9;
    for (const auto& [plo, phi] : patches) {
      if (zhi < plo || zlo > phi) continue;
      // Where the beam enters the patch.
      double hd = d0, hz = za;
      if (t < 0 && za > phi) {
        hd = (phi - sz) / t;
        hz = phi;
      } else if (t > 0 && za < plo) {
        hd = (plo - sz) / t;
        hz = plo;
      }
      const double r = std::hypot(hd, hz - sz);
      if (r >= cfg.min_range_m && r <= cfg.max_range_m) {
        return std::make_pair(BeamReturn{hd, hz}, c);
      }
      return std::nullopt;
    }
    d = std::max(d, d1 - cell / 8);  // jump to the cell's exit
  }
  return std::nullopt;
}

// The paper's prediction, one beam at a time: each beam of each fan walks the cells under it
// until its height inside a cell meets one of the cell's patches (unknown cells: ground at the
// last ground height seen along the beam, solid below a cell's lowest surface, as
// VisibilityPredictor assumes), then the returns of a fan are gap-filled by insert_scan's rule.
// Deliberately plain: it is the reference.
std::vector<std::uint8_t> per_beam_prediction(const MlsMap& map, const CellGrid<Region>& raster,
                                              CellIndex sensor, double floor_z,
                                              const VisibilityConfig& cfg) {
  std::vector<std::uint8_t> seen(raster.values.size(), 0);
  const double cell = map.cell_m();
  const double sz = floor_z + cfg.sensor_height_m;
  const Eigen::Vector2d o = map.center_of(sensor);
  const int beams =
      static_cast<int>(std::floor(cfg.vertical_fov_deg / cfg.elevation_step_deg + 1e-9)) + 1;
  const int n_az = static_cast<int>(std::lround(360.0 / cfg.azimuth_step_deg));
  const auto& mc = map.config();
  const auto mark = [&](CellIndex c) {
    if (const auto off = raster.offset(c)) seen[*off] = 1;
  };
  std::vector<std::optional<BeamReturn>> returns(static_cast<std::size_t>(beams));
  for (int a = 0; a < n_az; ++a) {
    const double az = 2 * M_PI * a / n_az;
    const Eigen::Vector2d dir(std::cos(az), std::sin(az));
    for (int k = 0; k < beams; ++k) {
      const double el = deg2rad(-cfg.vertical_fov_deg / 2 + k * cfg.elevation_step_deg);
      const auto hit = cast_beam(map, o, dir, sz, std::tan(el), floor_z, cfg);
      returns[static_cast<std::size_t>(k)].reset();
      if (!hit) continue;
      returns[static_cast<std::size_t>(k)] = hit->first;
      mark(hit->second);
    }
    if (!mc.fill_between_beams) continue;
    std::optional<BeamReturn> prev;
    for (int k = 0; k < beams; ++k) {
      const auto& r = returns[static_cast<std::size_t>(k)];
      if (!r) continue;
      if (prev && prev->z < sz && r->z < sz && prev->d > 0.3 && r->d > 0.3) {
        const double len = std::abs(r->d - prev->d);
        if (len >= cell && len <= mc.fill_max_gap_m &&
            std::abs(r->z - prev->z) <= mc.fill_max_slope * len) {
          const int steps = static_cast<int>(std::ceil(len / (0.5 * cell)));
          for (int s = 1; s < steps; ++s) {
            const double d = prev->d + (r->d - prev->d) * s / steps;
            const Eigen::Vector2d p = o + d * dir;
            mark(map.index_of(p.x(), p.y()));
          }
        }
      }
      prev = r;
    }
  }
  return seen;
}

double iou(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b) {
  std::size_t inter = 0, uni = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    inter += a[i] && b[i];
    uni += a[i] || b[i];
  }
  return uni ? static_cast<double>(inter) / static_cast<double>(uni) : 1.0;
}

nlohmann::json mean_sd(const std::vector<double>& v) {
  double m = 0, s2 = 0;
  for (double x : v) m += x;
  const auto n = static_cast<double>(v.size());
  m /= v.empty() ? 1.0 : n;
  for (double x : v) s2 += (x - m) * (x - m);
  return {{"mean", m}, {"sd", v.size() > 1 ? std::sqrt(s2 / (n - 1)) : 0.0}, {"n", v.size()}};
}

// Splits "paper,travel" into policies; throws for an unknown name.
std::vector<PlannerPolicy> parse_policies(const std::string& list) {
  std::vector<PlannerPolicy> out;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto p = parse_policy(name);
    if (!p) throw std::invalid_argument("unknown policy '" + name + "'");
    out.push_back(*p);
    begin = end + 1;
  }
  return out;
}

// A colour per policy for the charts (BGR).
cv::Scalar policy_color(PlannerPolicy p) {
  switch (p) {
    case PlannerPolicy::kPaper:
      return {180, 100, 30};
    case PlannerPolicy::kExhaustive:
      return {40, 40, 200};
    case PlannerPolicy::kTravel:
      return {60, 160, 40};
    case PlannerPolicy::kNearestFrontier:
      return {0, 140, 230};
    case PlannerPolicy::kRandom:
      return {140, 140, 140};
  }
  return {0, 0, 0};
}

// One run of the study: exact poses and matching off, so only the planning differs.
ClosedLoopConfig study_config(const World& world, PlannerPolicy p, int seed, int max_scans,
                              const PlannerConfig& travel) {
  ClosedLoopConfig cfg;
  cfg.planner.policy = p;
  cfg.planner.seed = static_cast<std::uint64_t>(seed);
  cfg.planner.visibility = VisibilityConfig::from_scanner(world.scanner);
  cfg.planner.travel_cost_per_m = travel.travel_cost_per_m;
  cfg.planner.travel_free_m = travel.travel_free_m;
  cfg.planner.screening_coarsening = travel.screening_coarsening;
  cfg.seed = static_cast<std::uint64_t>(seed);
  cfg.max_scans = max_scans;
  cfg.stop_at_coverage_pct = 95.0;
  cfg.matching.reset();
  return cfg;
}

// The coverage, detected area and path charts of the study, as one PNG.
bool write_chart(const std::vector<ChartSeries>& coverage_series,
                 const std::vector<ChartSeries>& detected_series,
                 const std::vector<ChartSeries>& path_series, const std::string& png) {
  ChartStyle coverage_style, detected_style, path_style;
  coverage_style.title = "scan-completed reachable ground, mean +- sd";
  coverage_style.y_label = "coverage (%)";
  coverage_style.references = {{95, "95 %"}};
  detected_style.title = "detected area (C + M), mean +- sd";
  detected_style.y_label = "area (m2)";
  detected_style.references = {{16500, "paper: 16,500 m2 in 13 scans"}};
  path_style.width_px = 2 * coverage_style.width_px;
  path_style.height_px = 300;
  path_style.title = "path driven, mean +- sd";
  path_style.y_label = "path (m)";
  cv::Mat row1, chart;
  cv::hconcat(render_coverage_chart(coverage_series, coverage_style),
              render_coverage_chart(detected_series, detected_style), row1);
  cv::vconcat(row1, render_coverage_chart(path_series, path_style), chart);
  const auto bytes = encode_png(chart);
  std::FILE* f = std::fopen(png.c_str(), "wb");
  const bool written = f && std::fwrite(bytes.data(), 1, bytes.size(), f) == bytes.size();
  if (f) std::fclose(f);
  if (!written) std::fprintf(stderr, "cannot write %s\n", png.c_str());
  return written;
}

int coverage_study(int seeds, const std::string& policies, const std::string& world_file,
                   int max_scans, const std::string& png, const PlannerConfig& travel) {
  std::vector<ChartSeries> coverage_series, detected_series, path_series;
  World world = load_world(world_file);
  world.pose_noise = PoseNoise{0, 0, 0};
  nlohmann::json out = {{"bench", "planner_coverage"},
                        {"seeds", seeds},
                        {"max_scans", max_scans},
                        {"travel_cost_per_m", travel.travel_cost_per_m},
                        {"travel_free_m", travel.travel_free_m},
                        {"screening_coarsening", travel.screening_coarsening}};
  for (const PlannerPolicy p : parse_policies(policies)) {
    std::vector<double> scans, path, detected13, plan_ms;
    nlohmann::json curves = nlohmann::json::array();
    const std::string name(policy_name(p));
    coverage_series.push_back({name, policy_color(p), {}});
    detected_series.push_back({name, policy_color(p), {}});
    path_series.push_back({name, policy_color(p), {}});
    int reached = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      const ClosedLoopConfig cfg = study_config(world, p, seed, max_scans, travel);
      double d13 = 0, ms = 0;
      nlohmann::json curve = {{"seed", seed},
                              {"detected_m2", nlohmann::json::array()},
                              {"coverage_pct", nlohmann::json::array()},
                              {"path_m", nlohmann::json::array()}};
      const LoopResult r =
          run_closed_loop(world, cfg, [&](const LoopStep& s, const MissionPipeline&) {
            if (s.scan == 13) d13 = s.detected_m2;
            ms += s.plan_ms;
            curve["detected_m2"].push_back(s.detected_m2);
            curve["coverage_pct"].push_back(s.coverage_pct);
            curve["path_m"].push_back(s.path_m);
          });
      curve["stopped_because"] = r.stopped_because;
      coverage_series.back().runs.push_back(curve["coverage_pct"].get<std::vector<double>>());
      detected_series.back().runs.push_back(curve["detected_m2"].get<std::vector<double>>());
      path_series.back().runs.push_back(curve["path_m"].get<std::vector<double>>());
      curves.push_back(curve);
      detected13.push_back(d13);
      plan_ms.push_back(ms / static_cast<double>(r.steps.size()));
      std::fprintf(stderr, "%s seed %d: %s scans to 95%%, path %.0f m\n",
                   std::string(policy_name(p)).c_str(), seed,
                   r.scans_to_95pct ? std::to_string(*r.scans_to_95pct).c_str() : "no",
                   r.path_to_95pct_m.value_or(0.0));
      if (!r.scans_to_95pct) continue;
      ++reached;
      scans.push_back(*r.scans_to_95pct);
      path.push_back(*r.path_to_95pct_m);
    }
    out[std::string(policy_name(p))] = {
        {"reached_95pct", reached},         {"scans_to_95pct", mean_sd(scans)},
        {"path_to_95pct_m", mean_sd(path)}, {"detected_after_13_m2", mean_sd(detected13)},
        {"plan_ms", mean_sd(plan_ms)},      {"curves", curves}};
  }
  if (!png.empty()) {
    if (!write_chart(coverage_series, detected_series, path_series, png)) return 1;
    out["png"] = png;
  }
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

// The campus with five scans across its middle, on open ground: the map the study plans on.
struct Campus {
  explicit Campus(const std::string& world_file)
      : world(load_world(world_file)),
        caster(world),
        truth(world, caster),
        target(world.target_region()),
        sensor(0, 0, world.scanner.mount_height_m) {
    for (std::size_t k = 0; k < kFirst.size(); ++k) {
      const Eigen::Vector2d& p = kFirst[k];
      robot = true_pose(p.x(), p.y(), world.ground_height(p.x(), p.y()));
      map.insert_scan(simulate_scan(caster, world.scanner, robot, k + 1), robot.isometry(), sensor);
      scan_points.push_back(p);
    }
  }
  // The true pose of a robot put down at (x, y) near height z: on the real surface, tilted with
  // the ground, as the bridge would stand it.
  Pose true_pose(double x, double y, double z) const {
    const auto hit = caster.cast({x, y, z + 1.0}, {0, 0, -1}, 0.0, 2.0);
    const double ground = hit ? z + 1.0 - hit->range : z;
    return truth.standing_pose(x, y, ground, 0.0);
  }
  PlanInput input() const { return {map, target, scan_points, {robot.x, robot.y, robot.z}}; }

  inline static const std::vector<Eigen::Vector2d> kFirst = {
      {80, 45}, {115, 42}, {60, 48}, {95, 100}, {130, 98}};
  World world;
  RayCaster caster;
  WorldTraversability truth;
  TargetRegion target;
  Eigen::Vector3d sensor;
  MlsMap map;
  std::vector<Eigen::Vector2d> scan_points;
  Pose robot;
};

// One planning step per policy on the five-scan map: best of 3 (the machine is shared).
nlohmann::json time_policies(const PlanInput& input, const PlannerConfig& base) {
  nlohmann::json policies = nlohmann::json::object();
  // "paper-full-screening": the baseline of the sparser screening, its sample through the
  // climbs' own fan.
  const std::vector<std::pair<PlannerPolicy, std::string>> runs = {
      {PlannerPolicy::kPaper, "paper"},
      {PlannerPolicy::kPaper, "paper-full-screening"},
      {PlannerPolicy::kExhaustive, "exhaustive"},
      {PlannerPolicy::kTravel, "travel"},
      {PlannerPolicy::kNearestFrontier, "nearest-frontier"},
      {PlannerPolicy::kRandom, "random"}};
  for (const auto& [p, name] : runs) {
    PlannerConfig cfg = base;
    cfg.policy = p;
    if (name == "paper-full-screening") cfg.screening_coarsening = 1;
    double best = 1e300, best_cpu = 1e300;
    Plan plan;
    for (int r = 0; r < 3; ++r) {
      const double c0 = cpu_ms();
      plan = plan_next_scan(input, cfg);
      best = std::min(best, plan.plan_ms);
      best_cpu = std::min(best_cpu, cpu_ms() - c0);
    }
    nlohmann::json j = {{"ms", best}, {"cpu_ms", best_cpu}, {"evaluations", plan.evaluations}};
    if (!plan.ranked.empty()) {
      const Candidate& c = plan.ranked.front();
      j["f"] = c.f;
      j["xy"] = {c.position.x(), c.position.y()};
      j["travel_m"] = c.travel_m;
    }
    policies[name] = j;
  }
  return policies;
}

// The cost of one prediction: the viewshed against the per-beam baseline, from the same cells
// with the same model (thin objects filling their cells, which the baseline does not refine),
// and how often the two agree on a cell.
nlohmann::json prediction_cost(const Campus& campus, const PlannerConfig& base) {
  const MlsMap& map = campus.map;
  const RegionMap regions = segment_regions(map, campus.target, campus.scan_points);
  const MovableRegion movable =
      movable_region(map, {campus.robot.x, campus.robot.y, campus.robot.z});
  VisibilityConfig plain = base.visibility;
  plain.thin_object_radius_m = 0;
  const VisibilityPredictor viewshed(map, regions.cells, plain);
  std::vector<CellIndex> sample;
  for (std::size_t o = 0; o < movable.patch.values.size() && sample.size() < 400; o += 37) {
    const CellIndex c = movable.patch.index_at(o);
    const Eigen::Vector2d xy = map.center_of(c);
    if (movable.patch.values[o] >= 0 && campus.target.contains(xy.x(), xy.y())) sample.push_back(c);
  }
  const auto floor_of = [&](CellIndex c) {
    return map.cell(c)->patches[movable.patch.values[*movable.patch.offset(c)]].mean_z;
  };
  auto ws = viewshed.workspace();
  auto t0 = Clock::now();
  for (const CellIndex c : sample) viewshed.visible_from(c, floor_of(c), ws);
  const double us_viewshed = ms_since(t0) * 1000 / static_cast<double>(sample.size());
  double agreement_sum = 0;
  const int baseline_samples = 5;
  double ms_baseline = 0;
  for (int k = 0; k < baseline_samples; ++k) {
    const CellIndex c = sample[static_cast<std::size_t>(k) * sample.size() / baseline_samples];
    t0 = Clock::now();
    const auto ref = per_beam_prediction(map, regions.cells, c, floor_of(c), plain);
    ms_baseline += ms_since(t0);
    std::vector<std::uint8_t> ours(regions.cells.values.size(), 0);
    for (const auto o : viewshed.visible_from(c, floor_of(c), ws)) ours[o] = 1;
    agreement_sum += iou(ours, ref);
  }
  const double us_baseline = ms_baseline * 1000 / baseline_samples;
  return {{"movable_m2", movable.area_m2()},
          {"us_per_evaluation_viewshed", us_viewshed},
          {"us_per_evaluation_per_beam_baseline", us_baseline},
          {"evaluation_speedup", us_baseline / us_viewshed},
          {"iou_viewshed_vs_per_beam", agreement_sum / baseline_samples}};
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0.0 : s / static_cast<double>(v.size());
}

// How well a planned scan was predicted: IoU of the cells predicted and really seen (all, and
// the unscanned ones), and the unscanned area really seen over that predicted.
struct PredictionCheck {
  double iou_all = 0, iou_new = 0;
  std::optional<double> gain_ratio;
};

PredictionCheck check_prediction(const MlsMap& map, const RegionMap& regions, const Candidate& b,
                                 const PointCloud& scan, const Pose& at,
                                 const Eigen::Vector3d& sensor, const VisibilityConfig& vis) {
  const auto& grid = regions.cells;
  const VisibilityPredictor predictor(map, grid, vis);
  auto pws = predictor.workspace();
  std::vector<std::uint8_t> predicted(grid.values.size(), 0), predicted_new(grid.values.size(), 0);
  const CellIndex bc = map.index_of(b.position.x(), b.position.y());
  for (const auto o : predictor.visible_from(bc, b.position.z(), pws)) {
    predicted[o] = 1;
    predicted_new[o] = grid.values[o] == Region::kUnscanned;
  }
  MlsMap alone;
  alone.insert_scan(scan, at.isometry(), sensor);
  std::vector<std::uint8_t> actual(grid.values.size(), 0), actual_new(grid.values.size(), 0);
  std::size_t new_u = 0;
  for (std::size_t o = 0; o < grid.values.size(); ++o) {
    if (grid.values[o] == Region::kOutside) {
      predicted[o] = predicted_new[o] = 0;
      continue;
    }
    actual[o] = alone.cell(grid.index_at(o)) != nullptr;
    actual_new[o] = actual[o] && grid.values[o] == Region::kUnscanned;
    new_u += actual_new[o];
  }
  PredictionCheck out{iou(predicted, actual), iou(predicted_new, actual_new), std::nullopt};
  if (b.gain_unscanned_m2 > 0) {
    out.gain_ratio = static_cast<double>(new_u) * grid.cell_m * grid.cell_m / b.gain_unscanned_m2;
  }
  return out;
}

bool same_ranked(const Plan& a, const Plan& b) {
  if (a.ranked.size() != b.ranked.size()) return false;
  for (std::size_t k = 0; k < a.ranked.size(); ++k) {
    if (a.ranked[k].position != b.ranked[k].position || a.ranked[k].f != b.ranked[k].f ||
        a.ranked[k].score != b.ranked[k].score)
      return false;
  }
  return true;
}

double share(std::size_t part, std::size_t whole) {
  return whole > 0 ? static_cast<double>(part) / static_cast<double>(whole) : 0.0;
}

// A closed loop from the five-scan map: each step plans with both `paper` (a new seed each
// step) and `exhaustive`, then scans at the exhaustive choice; the prediction for that scan is
// compared with the cells the scan then adds to the map. Both policies plan a second time with
// a memo kept over the loop (GainMemo, issue 19): the same plans, and what reuse saves.
nlohmann::json loop_study(Campus& campus, const PlannerConfig& base, int loop_steps) {
  std::vector<double> gaps, gaps_plain, iou_new, iou_all, gain_ratio, ms_paper, ms_exhaustive;
  std::vector<double> gaps_full_screening, ms_paper_full_screening;
  std::vector<double> ms_paper_memo, ms_exhaustive_memo, reused_paper, reused_exhaustive;
  GainMemo paper_memo, exhaustive_memo;
  bool memo_plans_same = true;
  double sum_f_paper = 0, sum_f_best = 0;
  for (int step = 0; step < loop_steps; ++step) {
    const PlanInput in = campus.input();
    PlannerConfig cfg = base;
    cfg.seed = static_cast<std::uint64_t>(1000 + step);
    cfg.policy = PlannerPolicy::kPaper;
    const Plan paper = plan_next_scan(in, cfg);
    cfg.screening_coarsening = 1;  // the sample through the climbs' own fan, the baseline
    const Plan full_screening = plan_next_scan(in, cfg);
    cfg.screening_coarsening = base.screening_coarsening;
    cfg.hill_climb_samples = 0;  // the paper's plain random starts, for comparison
    const Plan random_starts = plan_next_scan(in, cfg);
    cfg.hill_climb_samples = base.hill_climb_samples;
    cfg.policy = PlannerPolicy::kExhaustive;
    cfg.completion_weight = 0;  // the optimum of F alone
    const Plan best = plan_next_scan(in, cfg);
    if (best.ranked.empty()) break;
    ms_paper.push_back(paper.plan_ms);
    ms_paper_full_screening.push_back(full_screening.plan_ms);
    ms_exhaustive.push_back(best.plan_ms);
    PlanInput with_memo = in;
    with_memo.memo = &exhaustive_memo;
    const Plan best_memo = plan_next_scan(with_memo, cfg);
    cfg.policy = PlannerPolicy::kPaper;
    with_memo.memo = &paper_memo;
    const Plan paper_memo_plan = plan_next_scan(with_memo, cfg);
    memo_plans_same =
        memo_plans_same && same_ranked(best, best_memo) && same_ranked(paper, paper_memo_plan);
    ms_exhaustive_memo.push_back(best_memo.plan_ms);
    ms_paper_memo.push_back(paper_memo_plan.plan_ms);
    reused_exhaustive.push_back(share(best_memo.reused, best_memo.evaluations));
    reused_paper.push_back(share(paper_memo_plan.reused, paper_memo_plan.evaluations));
    const double f_best = best.ranked.front().f;
    const double f_paper = paper.ranked.empty() ? 0.0 : paper.ranked.front().f;
    const double f_random = random_starts.ranked.empty() ? 0.0 : random_starts.ranked.front().f;
    gaps.push_back((f_best - f_paper) / f_best);
    gaps_plain.push_back((f_best - f_random) / f_best);
    gaps_full_screening.push_back(
        (f_best - (full_screening.ranked.empty() ? 0.0 : full_screening.ranked.front().f)) /
        f_best);
    sum_f_best += f_best;
    sum_f_paper += f_paper;

    const Candidate& b = best.ranked.front();
    const Pose at = campus.true_pose(b.position.x(), b.position.y(), b.position.z());
    const PointCloud scan = simulate_scan(campus.caster, campus.world.scanner, at,
                                          static_cast<std::uint64_t>(100 + step));
    const PredictionCheck check =
        check_prediction(campus.map, best.regions, b, scan, at, campus.sensor, base.visibility);
    iou_new.push_back(check.iou_new);
    iou_all.push_back(check.iou_all);
    if (check.gain_ratio) gain_ratio.push_back(*check.gain_ratio);
    campus.map.insert_scan(scan, at.isometry(), campus.sensor);
    campus.scan_points.push_back({b.position.x(), b.position.y()});
    campus.robot = at;
  }
  return {{"loop_steps", gaps.size()},
          {"paper_gap_mean", mean_of(gaps)},
          {"paper_gap_max", gaps.empty() ? 0.0 : *std::max_element(gaps.begin(), gaps.end())},
          {"paper_random_starts_gap_mean", mean_of(gaps_plain)},
          {"paper_full_screening_gap_mean", mean_of(gaps_full_screening)},
          {"paper_full_screening_gap_max",
           gaps_full_screening.empty()
               ? 0.0
               : *std::max_element(gaps_full_screening.begin(), gaps_full_screening.end())},
          {"loop_ms_paper_full_screening_mean", mean_of(ms_paper_full_screening)},
          {"paper_f_share_of_optimum", sum_f_best > 0 ? sum_f_paper / sum_f_best : 1.0},
          {"loop_ms_paper_mean", mean_of(ms_paper)},
          {"loop_ms_exhaustive_mean", mean_of(ms_exhaustive)},
          {"loop_memo_plans_identical", memo_plans_same},
          {"loop_ms_paper_memo_mean", mean_of(ms_paper_memo)},
          {"loop_ms_exhaustive_memo_mean", mean_of(ms_exhaustive_memo)},
          {"loop_memo_reused_share_paper_mean", mean_of(reused_paper)},
          {"loop_memo_reused_share_exhaustive_mean", mean_of(reused_exhaustive)},
          {"prediction_iou_new_cells_mean", mean_of(iou_new)},
          {"prediction_iou_all_cells_mean", mean_of(iou_all)},
          {"actual_over_predicted_unscanned_gain_mean", mean_of(gain_ratio)}};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 3 && std::string(argv[1]) == "--coverage") {
    // --travel-cost X, --travel-free M and --screening K (PlannerConfig::screening_coarsening)
    // anywhere after the policies override the defaults.
    PlannerConfig travel;
    std::vector<std::string> rest;
    for (int i = 4; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--travel-cost" && i + 1 < argc) {
        travel.travel_cost_per_m = std::stod(argv[++i]);
      } else if (a == "--travel-free" && i + 1 < argc) {
        travel.travel_free_m = std::stod(argv[++i]);
      } else if (a == "--screening" && i + 1 < argc) {
        travel.screening_coarsening = std::stoi(argv[++i]);
      } else {
        rest.push_back(a);
      }
    }
    return coverage_study(
        std::stoi(argv[2]), argv[3],
        rest.size() > 0 ? rest[0] : SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json",
        rest.size() > 1 ? std::stoi(rest[1]) : 60, rest.size() > 2 ? rest[2] : "", travel);
  }
  Campus campus(argc > 1 ? argv[1] : SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  const int loop_steps = argc > 2 ? std::stoi(argv[2]) : 20;
  PlannerConfig base;
  base.threads = 2;
  base.visibility = VisibilityConfig::from_scanner(campus.world.scanner);

  nlohmann::json out = {{"bench", "planner_campus"},
                        {"map_scans", Campus::kFirst.size()},
                        {"threads", 2},
                        {"policies", time_policies(campus.input(), base)}};
  out.update(prediction_cost(campus, base));
  out.update(loop_study(campus, base, loop_steps));
  out["final_detected_m2"] =
      segment_regions(campus.map, campus.target, campus.scan_points).detected_m2();
  std::printf("%s\n", out.dump().c_str());
  return 0;
}

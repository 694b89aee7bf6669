#include "scanplan/registration/registration.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "pose_increment.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/registration/alignment_quality.hpp"
#include "scanplan/registration/ndt_icp.hpp"

namespace scanplan {
namespace {

using detail::metres;

constexpr std::array<std::pair<Method, std::string_view>, 5> kNames{{
    {Method::kNdtIcp, "ndt-icp"},
    {Method::kNdt, "ndt"},
    {Method::kIcp, "icp"},
    {Method::kGicp, "gicp"},
    {Method::kSearchGicp, "search-gicp"},
}};

RegistrationResult failed(std::string_view method, std::string message) {
  RegistrationResult r;
  r.method = std::string(method);
  r.message = std::move(message);
  return r;
}

// Why a settled result is not believed (RegistrationConfig's sanity check), or nothing; the
// weakest constraint is not checked for a result that held on restarts.
std::optional<std::string> rejection(const AlignmentQuality& q, const RegistrationConfig& c,
                                     bool held_on_restart = false) {
  char buf[96];
  if (q.inlier_ratio < c.min_inlier_ratio) {
    std::snprintf(buf, sizeof buf, "%.1f%% (at least %.1f%% needed)", 100 * q.inlier_ratio,
                  100 * c.min_inlier_ratio);
    return "only " + std::string(buf) + " of the source points lie within " +
           metres(c.inlier_distance_m) +
           " of the target: the scans do not overlap enough, or the match is wrong";
  }
  const double min_constraint = c.dof == Dof::k4 ? c.min_constraint : c.min_constraint_6dof;
  if (q.weakest_constraint < min_constraint && !held_on_restart) {
    std::snprintf(buf, sizeof buf, "%.4f (at least %.4f needed)", q.weakest_constraint,
                  min_constraint);
    return std::string(
               "the matched surfaces leave the pose nearly free in one direction "
               "(weakest constraint ") +
           buf + "): a corridor or a single wall, along which the match cannot be trusted";
  }
  return std::nullopt;
}

// Whether GICP restarted from `at` shifted along x and y and turned either way comes back to it
// every time (RegistrationConfig::restart_check).
bool holds_on_restart(const GicpMatcher& gicp, const Eigen::Isometry3d& at,
                      const RegistrationConfig& c) {
  const Eigen::Vector3d pivot = at.translation();
  const double turn = deg2rad(c.restart_turn_deg);
  std::vector<Eigen::Isometry3d> moves;
  for (const double s : {-c.restart_shift_m, c.restart_shift_m}) {
    moves.emplace_back(Eigen::Translation3d(s, 0, 0));
    moves.emplace_back(Eigen::Translation3d(0, s, 0));
  }
  for (const double t : {-turn, turn}) {
    moves.emplace_back(Eigen::Translation3d(pivot) *
                       Eigen::AngleAxisd(t, Eigen::Vector3d::UnitZ()) *
                       Eigen::Translation3d(-pivot));
  }
  for (const Eigen::Isometry3d& move : moves) {
    const RegistrationResult r = gicp.align(move * at, c.dof);
    const Eigen::Isometry3d off = at.inverse() * r.transform;
    if (!r.converged || off.translation().norm() > c.restart_tolerance_m ||
        Eigen::AngleAxisd(off.linear()).angle() > deg2rad(c.restart_tolerance_deg)) {
      return false;
    }
  }
  return true;
}

// Another result that passed the check almost as well as `best` but lies elsewhere: why the
// match is ambiguous, or nothing. How well is the inlier count times the prior (prior_weight).
std::optional<std::string> ambiguous(
    const Eigen::Isometry3d& best, double support,
    const std::vector<std::pair<Eigen::Isometry3d, double>>& passed, const PoseSearchConfig& c) {
  for (const auto& [other, other_support] : passed) {
    const Eigen::Isometry3d off = best.inverse() * other;
    const double metres = off.translation().head<2>().norm();
    const double degrees = rad2deg(Eigen::AngleAxisd(off.linear()).angle());
    if ((metres > c.min_separation_m || degrees > c.min_separation_deg) &&
        other_support >= c.ambiguity_ratio * support) {
      char why[160];
      std::snprintf(why, sizeof why,
                    "ambiguous: a pose %.1f m and %.1f° away fits almost as well (a repeated "
                    "structure); not believed",
                    metres, degrees);
      return std::string(why);
    }
  }
  return std::nullopt;
}

// GICP from the peaks of the pose search, best first (from `initial` when the search finds
// none), until a result passes the sanity check; if none does, the one that came closest. A
// search peak can be a false one (a facade shifted along itself, a repeated row of cars); the
// check, not the search score, tells which refinement to believe.
RegistrationResult align_search_gicp(const PointCloud& target, const PointCloud& source,
                                     const Eigen::Isometry3d& initial, const RegistrationConfig& c,
                                     const MatchViews& views) {
  const GicpMatcher gicp(target, source, c.gicp, views);
  const AlignmentJudge judge(target, gicp.unthinned_target_tree());
  // Which result to keep is judged on every third source point, a third of the cost; the kept
  // one is judged again on all of them (register_with).
  PointCloud sample;
  for (std::size_t i = 0; i < source.size(); i += 3) sample.points.push_back(source.points[i]);
  std::vector<PoseHypothesis> starts = search_poses(target, source, initial, c.search);
  if (starts.empty()) starts.push_back({initial, 0});
  RegistrationResult best;
  AlignmentQuality best_q;
  int best_rank = -1;
  double best_support = 0;  // inliers times the prior
  int iterations = 0;
  const bool check_ambiguity = c.search.ambiguity_ratio > 0;
  std::vector<std::pair<Eigen::Isometry3d, double>> passed;  // transform, support
  for (const PoseHypothesis& start : starts) {
    RegistrationResult r = gicp.align(start.transform, c.dof);
    iterations += r.iterations;
    const AlignmentQuality q = judge.evaluate(sample, r.transform, c.dof, c.score_max_distance_m,
                                              c.inlier_distance_m, r.converged);
    const int rank = r.converged ? (rejection(q, c) ? 1 : 2) : 0;
    const double support =
        static_cast<double>(q.inliers) * prior_weight(c.search, initial, r.transform);
    if (rank == 2) passed.emplace_back(r.transform, support);
    if (rank > best_rank || (rank == best_rank && support > best_support)) {
      best = std::move(r);
      best_q = q;
      best_rank = rank;
      best_support = support;
    }
    if (best_rank == 2 && !check_ambiguity) break;
  }
  if (best_rank == 2 && check_ambiguity) {
    if (const auto rival = ambiguous(best.transform, best_support, passed, c.search)) {
      best.converged = false;
      best.message = *rival;
    }
  }
  // Refused only for its weakest constraint: restarts from around it tell whether it holds.
  const double shift = (best.transform.translation() - initial.translation()).head<2>().norm();
  if (best_rank == 1 && c.restart_check && best_q.weakest_constraint >= c.restart_min_constraint &&
      shift <= c.restart_max_shift_m && !rejection(best_q, c, /*held_on_restart=*/true)) {
    best.held_on_restart = holds_on_restart(gicp, best.transform, c);
  }
  best.iterations = iterations;
  return best;
}

RegistrationResult align_ours(const PointCloud& target, const PointCloud& source,
                              const Eigen::Isometry3d& initial, Method method,
                              const RegistrationConfig& c, const MatchViews& views) {
  switch (method) {
    case Method::kNdtIcp:
      return align_ndt_icp(target, source, initial, c.dof, c.ndt, c.icp);
    case Method::kNdt:
      return align_narrower_ndt(target, source, initial, c.dof, c.ndt);
    case Method::kIcp:
      return align_line_segment_icp(target, source, initial, c.dof, c.icp);
    case Method::kGicp:
      return align_gicp(target, source, initial, c.dof, c.gicp, views);
    case Method::kSearchGicp:
      return align_search_gicp(target, source, initial, c, views);
  }
  return failed(method_name(method), "unknown method");
}

}  // namespace

std::optional<Method> parse_method(std::string_view name) {
  for (const auto& [method, text] : kNames) {
    if (text == name) return method;
  }
  return std::nullopt;
}

std::string_view method_name(Method method) {
  for (const auto& [m, text] : kNames) {
    if (m == method) return text;
  }
  return "unknown";
}

namespace {

// The q-quantile of `values` (reordered), which must not be empty.
float quantile(std::vector<float>& values, double q) {
  const auto at =
      values.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), at, values.end());
  return *at;
}

}  // namespace

double scene_range_m(const PointCloud& cloud) {
  std::vector<float> ranges;
  ranges.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    if (p.allFinite()) ranges.push_back(p.norm());
  }
  if (ranges.empty()) return 0;
  return quantile(ranges, 0.9);
}

double open_range_m(const PointCloud& cloud) {
  constexpr int kSectors = 36;
  constexpr std::size_t kMinSectorPoints = 20;
  std::array<std::vector<float>, kSectors> sectors;
  std::size_t finite = 0;
  for (const auto& p : cloud.points) {
    if (!p.allFinite()) continue;
    ++finite;
    const double turn = (std::atan2(p.y(), p.x()) + M_PI) / (2 * M_PI);
    sectors[std::clamp(static_cast<int>(turn * kSectors), 0, kSectors - 1)].push_back(p.norm());
  }
  std::vector<float> reach;
  for (auto& sector : sectors) {
    if (sector.size() >= kMinSectorPoints) reach.push_back(quantile(sector, 0.9));
  }
  // Too few points for any sector to say: over all of them.
  if (reach.empty()) return finite ? scene_range_m(cloud) : 0;
  return quantile(reach, 0.9);
}

RegistrationConfig scale_lengths(const RegistrationConfig& config, double factor) {
  RegistrationConfig c = config;
  c.voxel_m *= factor;
  c.icp.max_correspondence_m *= factor;
  c.icp.min_correspondence_m *= factor;
  c.icp.source_voxel_m *= factor;
  c.icp.translation_tolerance_m *= factor;
  c.score_max_distance_m *= factor;
  for (GicpStage& stage : c.gicp.stages) {
    stage.voxel_m *= factor;
    stage.source_voxel_m *= factor;
    stage.max_correspondence_m *= factor;
  }
  c.gicp.translation_tolerance_m *= factor;
  c.restart_shift_m *= factor;
  c.restart_tolerance_m *= factor;
  c.search.cell_m *= factor;
  c.search.source_voxel_m *= factor;
  c.inlier_distance_m *= factor;
  // NDT's tolerances and step bounds are already relative to the cell size.
  return c;
}

namespace {

// How far the scanner sees in `target`, measured as `config` says; 0 when lengths are not
// adapted to the scene.
double measured_range(const PointCloud& target, const RegistrationConfig& config) {
  if (!config.adapt_to_scene) return 0;
  return config.range_by_direction ? open_range_m(target) : scene_range_m(target);
}

// Below a hundredth of the outdoor scale the data is something else (a table-top scan); the
// floor keeps lengths from collapsing to nothing on a handful of points.
double scale_for(double range, double reference) {
  if (!(reference > 0) || !(range > 0)) return 1.0;
  return std::clamp(range / reference, 0.01, 1.0);
}

// adapted_config for a target whose range was measured already (the measure is a pass over
// every point: a whole scan's costs milliseconds).
RegistrationConfig adapted_to(double range, const RegistrationConfig& config) {
  RegistrationConfig c = scale_lengths(config, scale_for(range, config.reference_scene_range_m));
  const double cells = scale_for(range, config.paper_scene_range_m);
  for (double& cell : c.ndt.cell_sizes_m) cell *= cells;
  return c;
}

}  // namespace

double length_scale(const PointCloud& target, const RegistrationConfig& config) {
  return scale_for(measured_range(target, config), config.reference_scene_range_m);
}

RegistrationConfig adapted_config(const PointCloud& target, const RegistrationConfig& config) {
  return adapted_to(measured_range(target, config), config);
}

RegistrationResult register_scans(const PointCloud& target, const PointCloud& source,
                                  const Eigen::Isometry3d& initial, Method method,
                                  const RegistrationConfig& config, const MatchViews& views) {
  return register_with(
      target, source, initial, method_name(method),
      [method](const PointCloud& t, const PointCloud& s, const Eigen::Isometry3d& start,
               const RegistrationConfig& c, double,
               const MatchViews& v) { return align_ours(t, s, start, method, c, v); },
      config, views);
}

RegistrationResult register_with(const PointCloud& target, const PointCloud& source,
                                 const Eigen::Isometry3d& initial, std::string_view method,
                                 const Aligner& align, const RegistrationConfig& config,
                                 const MatchViews& views) {
  if (target.empty()) return failed(method, "the target cloud is empty");
  if (source.empty()) return failed(method, "the source cloud is empty");
  if (!initial.matrix().allFinite()) {
    return failed(method, "the initial transform is not finite");
  }
  const double range = measured_range(target, config);
  const double scale = scale_for(range, config.reference_scene_range_m);
  const RegistrationConfig c = adapted_to(range, config);
  const std::vector<std::uint32_t> t_kept = voxel_kept(target, c.voxel_m);
  const std::vector<std::uint32_t> s_kept = voxel_kept(source, c.voxel_m);
  const PointCloud t = picked(target, t_kept), s = picked(source, s_kept);
  MatchViews thinned_views;  // unknown unless both describe their clouds
  if (views.target.fit(target.size()) && views.source.fit(source.size())) {
    thinned_views = {views.target.picked(t_kept), views.source.picked(s_kept)};
  }
  const std::size_t need = std::max<std::size_t>(c.min_points, 1);
  if (t.size() < need || s.size() < need) {
    return failed(method, "too few points to match: target " + std::to_string(t.size()) +
                              ", source " + std::to_string(s.size()) + " after thinning to " +
                              metres(c.voxel_m) + " voxels (at least " + std::to_string(need) +
                              " each are needed)");
  }

  const auto started = std::chrono::steady_clock::now();
  RegistrationResult r = align(t, s, initial, c, scale, thinned_views);
  r.time_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
  r.method = std::string(method);

  const AlignmentQuality q =
      evaluate_alignment(t, s, r.transform, c.dof, c.score_max_distance_m, c.inlier_distance_m,
                         /*with_constraint=*/r.converged || r.ran_out);
  r.score = q.score;
  r.rmse = q.rmse;
  r.inlier_ratio = q.inlier_ratio;
  if (r.converged) {
    r.weakest_constraint = q.weakest_constraint;
    r.information = q.information;
    if (std::optional<std::string> why = rejection(q, c, r.held_on_restart)) {
      r.converged = false;
      r.message = std::move(*why);
    } else if (r.held_on_restart && rejection(q, c)) {
      char buf[64];
      std::snprintf(buf, sizeof buf, "%.4f", q.weakest_constraint);
      r.message = std::string("the surfaces fix the pose only weakly (weakest constraint ") + buf +
                  "), but GICP restarted around the result came back to it each time";
    }
  } else if (r.ran_out && q.inlier_ratio >= c.min_inlier_ratio) {
    // Where the solver stopped, the scans overlap: a weak constraint there is the reason.
    if (std::optional<std::string> why = rejection(q, c)) r.message = *why + "; " + r.message;
  }
  return r;
}

}  // namespace scanplan

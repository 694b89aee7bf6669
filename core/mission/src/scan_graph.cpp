#include "scanplan/mission/scan_graph.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

#include "scanplan/geometry/pose_information.hpp"
#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/mission/ahead_of_turn.hpp"

namespace scanplan {
namespace {

Eigen::Matrix4d diagonal_information(double sigma_xy_m, double sigma_z_m, double sigma_yaw_rad) {
  return Eigen::Vector4d(1 / (sigma_xy_m * sigma_xy_m), 1 / (sigma_xy_m * sigma_xy_m),
                         1 / (sigma_z_m * sigma_z_m), 1 / (sigma_yaw_rad * sigma_yaw_rad))
      .asDiagonal();
}

// A match's information as the graph takes it: per unit point variance over σ², plus a prior
// far weaker than any match (10 m, 10°) so that a direction no surface fixed stays invertible.
Eigen::Matrix4d match_information(const Eigen::Matrix4d& per_point, double sigma_m) {
  return per_point / (sigma_m * sigma_m) + diagonal_information(10.0, 10.0, deg2rad(10.0));
}

// Per edge of a graph of `edges` edges: whether the solve set it aside as an outlier.
std::vector<std::uint8_t> outlier_flags(std::size_t edges, const GraphSolveReport& solve) {
  std::vector<std::uint8_t> outlier(edges, 0);
  for (const std::size_t e : solve.outliers) outlier[e] = 1;
  return outlier;
}

}  // namespace

Pose level(Pose pose) {
  pose.roll = 0;
  pose.pitch = 0;
  return pose;
}

PointCloud levelled(PointCloud scan, const Pose& pose) {
  const Eigen::Matrix3f tilt = (Eigen::AngleAxisd(pose.pitch, Eigen::Vector3d::UnitY()) *
                                Eigen::AngleAxisd(pose.roll, Eigen::Vector3d::UnitX()))
                                   .toRotationMatrix()
                                   .cast<float>();
  for (auto& p : scan.points) p = tilt * p;
  return scan;
}

RegistrationConfig pair_registration() {
  RegistrationConfig c;
  c.range_by_direction = true;
  return c;
}

RegistrationConfig widened(RegistrationConfig config, const MoveUncertainty& prior) {
  config.search.prior_sigma_xy_m = prior.xy_m;
  config.search.prior_sigma_yaw_deg = prior.yaw_deg;
  config.search.ambiguity_ratio = 0.8;
  // A result the surfaces fix only weakly is believed on restarts as far from its start as the
  // start may be off (4σ, as restart_max_shift_m's 4 m is of the absolute sensors' 1 m; never
  // beyond the widest search): after drives of 90–130 m the odometry was 6–7 m off, and right
  // matches there (1–3 cm from the truth) were refused untried (issue 17).
  config.restart_max_shift_m =
      std::max(config.restart_max_shift_m, std::min(4 * prior.xy_m, kWidestSearchM));
  const double xy = std::min(3 * prior.xy_m, kWidestSearchM);
  const double yaw = std::min(3 * prior.yaw_deg, kWidestSearchDeg);
  if (xy <= config.search.xy_range_m && yaw <= config.search.yaw_range_deg) return config;
  config.search.xy_range_m = std::max(config.search.xy_range_m, xy);
  config.search.yaw_range_deg = std::max(config.search.yaw_range_deg, yaw);
  config.search.hypotheses = std::max(config.search.hypotheses, 5);
  return config;
}

MoveUncertainty ScanGraph::odometry_uncertainty(const RelativePose& move, double driven_m) const {
  if (noise_.model == OdometryModel::kDrift) {
    // The robot drives around what is in its way: the path is longer than the straight line
    // between the two reports, and the drift grows with the path.
    const double d = std::max(config_.path_factor * std::hypot(move.x, move.y), driven_m);
    return {std::max(noise_.xy_drift_fraction * d, config_.min_odometry_sigma_m),
            std::max(noise_.z_drift_fraction * d, config_.min_odometry_sigma_m),
            std::max(noise_.yaw_drift_deg_per_10m * d / 10.0, config_.min_odometry_sigma_deg)};
  }
  // Two independent fixes: the difference has twice their variance, and the move is measured
  // in the first one's frame, whose heading error swings it sideways by its length (on the
  // campus, moves of 60–100 m with σ 5° were 5–17 m off). Only where two consecutive fixes are
  // compared (a pair's search, whether two far corrections agree): the graph ties each fix to
  // the map frame itself (add_fix).
  const double xy = std::max(noise_.xy_sigma_m, config_.min_odometry_sigma_m);
  const double yaw = std::max(noise_.yaw_sigma_deg, config_.min_odometry_sigma_deg);
  const double swing = std::hypot(move.x, move.y) * deg2rad(yaw);
  return {std::sqrt(2 * xy * xy + swing * swing),
          std::sqrt(2.0) * std::max(noise_.z_sigma_m, config_.min_odometry_sigma_m),
          std::sqrt(2.0) * yaw};
}

std::optional<std::size_t> ScanGraph::last_anchored_of(const std::string& track) const {
  for (std::size_t i = tracks_.size(); i-- > 0;) {
    if (tracks_[i] == track && anchored_[i]) return i;
  }
  return std::nullopt;
}

std::optional<MoveUncertainty> ScanGraph::prior_uncertainty(const std::string& track,
                                                            const Pose& reported,
                                                            double driven_m) const {
  const auto from = last_anchored_of(track);
  if (!from || noise_.model != OdometryModel::kDrift) return std::nullopt;
  // The robot's reports from that scan on, then `reported`, each with the drive to it.
  std::vector<std::pair<const Pose*, double>> stops;
  for (std::size_t i = *from; i < tracks_.size(); ++i) {
    if (tracks_[i] == track) stops.emplace_back(&reported_[i], driven_[i]);
  }
  stops.emplace_back(&reported, driven_m);
  MoveUncertainty u;
  for (std::size_t s = 1; s < stops.size(); ++s) {
    const RelativePose move = relative_pose(*stops[s - 1].first, *stops[s].first);
    const MoveUncertainty m = odometry_uncertainty(move, stops[s].second);
    const double swing = std::hypot(move.x, move.y) * deg2rad(u.yaw_deg);
    u.xy_m = std::sqrt(u.xy_m * u.xy_m + m.xy_m * m.xy_m + swing * swing);
    u.z_m = std::hypot(u.z_m, m.z_m);
    u.yaw_deg = std::hypot(u.yaw_deg, m.yaw_deg);
  }
  return u;
}

ScanGraph::ScanGraph(ScanGraphConfig config, PoseNoise noise)
    : config_(std::move(config)), noise_(noise), graph_(config_.solver), frame_(noise) {}

std::optional<std::size_t> ScanGraph::last_of(const std::string& track) const {
  const auto it = last_of_track_.find(track);
  if (it == last_of_track_.end()) return std::nullopt;
  return it->second;
}

GraphUpdate ScanGraph::add(const PointCloud& scan, const Placement& where, bool tentative,
                           const Viewpoints& scanner) {
  const MoveUncertainty uncertain =
      where.matched && !tentative ? MoveUncertainty{}
                                  : prior_uncertainty(where.track, where.reported, where.driven_m)
                                        .value_or(MoveUncertainty{});
  const std::size_t k = graph_.add_node(where.placed);
  const RegistrationConfig adapted = adapted_config(scan, config_.registration);
  thinned_.push_back(std::make_shared<const PointCloud>(
      levelled(voxel_downsample(scan, adapted.voxel_m), where.placed)));
  thinned_voxel_.push_back(adapted.voxel_m);
  scanners_.push_back(scanner);
  reported_.push_back(where.reported);
  driven_.push_back(where.driven_m);
  tracks_.push_back(where.track);
  const bool matched = where.matched && !tentative;
  anchored_.push_back(k == 0 || matched ? 1 : 0);
  uncertain_.push_back(uncertain);
  pending_.emplace_back();
  pending_map_.emplace_back();
  const std::optional<std::size_t> previous = last_of(where.track);
  previous_.push_back(previous.value_or(kNoNode));
  if (noise_.model == OdometryModel::kAbsolute) {
    if (k > 0) add_fix(k);
  } else if (previous) {
    add_odometry(*previous, k);
  }
  last_of_track_[where.track] = k;

  GraphUpdate update;
  match_pairs(k, matched, update);
  if (matched) {
    add_match_to_map(k, where.placed, where.information, "map");
    confirm_by_odometry(k);  // the robot's scan before may be waiting for this one
  }
  if (where.matched && tentative) offer_match_to_map(k, where.placed, where.information);
  update.solve = solve();
  return update;
}

// Whether `b` placed at `b_placed` lies where the robot's odometry puts it from `a` placed at
// `a_placed`, within three of the move's σ (at least 0.5 m and 1°, at most 5 m and 10°).
bool ScanGraph::odometry_agrees(std::size_t a, const Pose& a_placed, std::size_t b,
                                const Pose& b_placed) const {
  const RelativePose move = relative_pose(reported_[a], reported_[b]);
  const Pose predicted = compose(a_placed, move, b_placed.roll, b_placed.pitch);
  const MoveUncertainty u = odometry_uncertainty(move, driven_between(a, b));
  const double off_m = std::hypot(predicted.x - b_placed.x, predicted.y - b_placed.y);
  const double off_deg = std::abs(rad2deg(std::remainder(predicted.yaw - b_placed.yaw, 2 * M_PI)));
  // Never looser than a few metres: a look-alike lies a building's depth off (16 m on the
  // campus), and a long drive's own error must not hide that. A look-alike is a shift, not a
  // turn of a few degrees; the heading may be as far off as the drive says, short of a turn that
  // would make a different structure match: on the campus loop, correct pairs of matches 50–60 m
  // apart were 0.7–3.4 m and 3.2–4.1° off their odometry, and a 3 m / 3° bound kept them out.
  return off_m <= std::clamp(3 * std::sqrt(2.0) * u.xy_m, 0.5, 5.0) &&
         off_deg <= std::clamp(3 * u.yaw_deg, 1.0, 10.0);
}

// The robot's latest scan before `k` whose map match waits for confirmation (pending_map_),
// when only scans no match placed lie between the two (at most kMaxSkipped), else kNoNode: the
// odometry over those drives still relates them. On the campus loop a correct far match was
// lost when the robot's next scan stood in a corridor and was refused, and the scan stayed out
// of the map, 3 m off.
std::size_t ScanGraph::waiting_before(std::size_t k) const {
  std::size_t p = previous_[k];
  for (std::size_t skipped = 0; p != kNoNode; ++skipped, p = previous_[p]) {
    if (pending_map_[p]) return p;
    if (anchored_[p] || skipped == kMaxSkipped) break;
  }
  return kNoNode;
}

// The path the robot drove from scan `a` to its later scan `b` (Placement::driven_m summed
// over the drives between), or 0 where a drive's path is unknown or `b` does not follow `a`.
double ScanGraph::driven_between(std::size_t a, std::size_t b) const {
  double sum = 0;
  for (std::size_t n = b; n != a; n = previous_[n]) {
    if (n == kNoNode || n < a || !(driven_[n] > 0)) return 0;
    sum += driven_[n];
  }
  return sum;
}

// A map match that corrected the pose further than the sensors usually err (the search reached
// farther because the robot drove far since its last anchored scan) is believed only when the
// robot's previous scan, also corrected that far by its own map match, lies where the odometry
// between the two says: both then carry the same drift, which a look-alike found in a repeated
// structure would not (it lies one building's depth off for one scan, elsewhere for the other).
void ScanGraph::confirm_by_odometry(std::size_t k) {
  // Two far corrections, each its own map match, agreeing: both are believed. The robot's
  // anchored scan before a waiting one says nothing (matching started from it and the
  // odometry); the one after it, placed by its own match, does (its match started elsewhere),
  // also across scans no match placed (waiting_before).
  const std::size_t p = waiting_before(k);
  if (p != kNoNode && pending_map_[p] && pending_map_[k] &&
      odometry_agrees(p, placed_now(p, *pending_map_[p]), k, placed_now(k, *pending_map_[k]))) {
    believe_waiting(p);
    believe_waiting(k);
    return;
  }
  if (p != kNoNode && pending_map_[p] && anchored_[k] && !pending_map_[k] &&
      odometry_agrees(p, placed_now(p, *pending_map_[p]), k, graph_.pose(k))) {
    believe_waiting(p);
  }
}

std::string ScanGraph::outside_reason(std::size_t scan) const {
  if (anchored_.at(scan)) return "";
  if (const std::optional<MapCandidate>& c = pending_map_[scan]) {
    const Pose matched = placed_now(scan, *c);
    const Pose& odometry = graph_.pose(scan);
    char off[32];
    std::snprintf(off, sizeof off, "%.2f m",
                  std::hypot(matched.x - odometry.x, matched.y - odometry.y));
    return std::string("its map match puts it ") + off +
           " from where the odometry does, farther than the odometry usually errs: it waits for "
           "the robot's next scan, placed by its own match, to agree";
  }
  if (!pending_[scan].empty())
    return "a pairwise match with a scan in the map waits for a second that agrees";
  return "no match ties it to the map";
}

void ScanGraph::believe_waiting(std::size_t scan) {
  const MapCandidate c = *pending_map_[scan];
  pending_map_[scan].reset();
  tie_to_map(scan, c, "map-confirmed");
}

// The match is kept against the anchored scan nearest to it as the map stood when it ran: the
// match said where the scan lies relative to the map as it was, and by the time it is believed
// the graph may have moved that part of the map (before, the edge took the reference's pose at
// confirmation, and a move in between went into the edge as an error).
void ScanGraph::offer_match_to_map(std::size_t scan, const Pose& placed,
                                   const Eigen::Matrix4d& information) {
  pending_map_[scan] = as_found(scan, placed, information);
  if (!pending_map_[scan]) return;
  confirm_by_odometry(scan);
  // A re-match of an older scan: the robot's scan after it may already be in the map.
  for (std::size_t n = scan + 1; n < previous_.size() && pending_map_[scan]; ++n) {
    if (waiting_before(n) == scan) confirm_by_odometry(n);
  }
}

GraphSolveReport ScanGraph::solve() {
  GraphSolveReport report = graph_.optimise();
  update_anchors(report);
  if (confirm_waiting(report)) {
    const double first_ms = report.time_ms;
    report = graph_.optimise();
    report.time_ms += first_ms;
    update_anchors(report);
  }
  return report;
}

// Whether pose `a` and `b` of one scan agree as two matches of it must (agree_m / _deg).
bool ScanGraph::agree(const Pose& a, const Pose& b) const {
  const PoseChange d = pose_change(a, b);
  return d.metres <= config_.agree_m && d.degrees <= config_.agree_deg;
}

// A far map match waiting for its robot's next scan (pending_map_) is believed, too, when a
// pairwise match with a later scan that is in the map now puts it where the map match did. That
// scan was placed without this one (not in the map), the pair matched their own points, and a
// look-alike would have to fool both to the centimetre. The odometry to the next scan is far
// rougher: on the campus loop (drifting odometry) two correct matches 52 m apart were 3.4 m and
// 3.2° off the odometry between them, and the scan stayed out of the map, metres off.
bool ScanGraph::later_pair_confirms(std::size_t scan, const GraphEdge& edge) const {
  const std::size_t other = edge.from == scan ? edge.to : edge.from;
  return pending_map_[scan] && other > scan && anchored_[other] &&
         agree(implied(edge, scan), placed_now(scan, *pending_map_[scan]));
}

// What confirms a waiting map match may come after the scan that could: the robot's next scan
// tied in by pairs or a re-match (confirm_by_odometry), a pair matched while both ends were
// outside the map whose later end is in it now (later_pair_confirms).
bool ScanGraph::confirm_waiting(const GraphSolveReport& solve) {
  bool any = false;
  for (std::size_t n = 0; n < graph_.size(); ++n) {
    const std::size_t p = waiting_before(n);
    if (p == kNoNode || anchored_[p] || !anchored_[n]) continue;
    confirm_by_odometry(n);
    any = any || !pending_map_[p];
  }
  const std::vector<std::uint8_t> outlier = outlier_flags(graph_.edges().size(), solve);
  for (std::size_t e = 0; e < outlier.size(); ++e) {  // believing adds edges, none a pair
    if (outlier[e] || anchors_[e] != kNoNode || origins_[e] != "pair-search") continue;
    const GraphEdge edge = graph_.edges()[e];  // a copy: believing adds edges
    for (const std::size_t scan : {edge.from, edge.to}) {
      if (anchored_[scan] || !later_pair_confirms(scan, edge)) continue;
      believe_waiting(scan);
      any = true;
    }
  }
  return any;
}

void ScanGraph::add_odometry(std::size_t from, std::size_t to) {
  const RelativePose move = relative_pose(reported_[from], reported_[to]);
  const MoveUncertainty u = odometry_uncertainty(move, driven_[to]);
  graph_.add_edge({from, to, move, diagonal_information(u.xy_m, u.z_m, deg2rad(u.yaw_deg)),
                   EdgeKind::kOdometry});
  origins_.emplace_back("odometry");
  anchors_.push_back(kNoNode);
}

// An absolute fix says where the scan lies in the world, each independently of the others. As
// the move between two consecutive fixes it was measured in the first one's frame, whose heading
// error swings it sideways by its length: a scan no match placed ended 22–37 m from the truth
// after a 147 m move from a fix 15° off (3σ), and a re-match started there could not find it
// (issue 15). Carried into the map frame by the frame the anchored scans measure, the fix is off
// by about one scan's sensor error, however far the robot drove (SensorFrame::spread).
void ScanGraph::add_fix(std::size_t k) {
  const auto [measured, information] = fix_of(k);
  graph_.add_edge({0, k, measured, information, EdgeKind::kOdometry});
  fix_edges_.push_back(graph_.edges().size() - 1);
  origins_.emplace_back("fix");
  anchors_.push_back(kNoNode);
}

// The fix of scan `k` (k > 0) seen from the first scan, which is the map frame's and held fixed,
// and how sure it is.
std::pair<RelativePose, Eigen::Matrix4d> ScanGraph::fix_of(std::size_t k) const {
  const MoveUncertainty u = frame_.spread(reported_[k]);
  const double xy = std::max(u.xy_m, config_.min_odometry_sigma_m);
  const double z = std::max(u.z_m, config_.min_odometry_sigma_m);
  const double yaw = deg2rad(std::max(u.yaw_deg, config_.min_odometry_sigma_deg));
  return {relative_pose(graph_.pose(0), frame_.to_map(reported_[k])),
          diagonal_information(xy, z, yaw)};
}

void ScanGraph::set_sensor_frame(const SensorFrame& frame) {
  frame_ = frame;
  for (std::size_t i = 0; i < fix_edges_.size(); ++i) {
    const auto [measured, information] = fix_of(i + 1);
    graph_.set_measurement(fix_edges_[i], measured, information);
  }
}

// The scan-to-map match placed the scan against the anchored scans around it; the graph has no
// node for "the map", so the result ties the scan to the nearest anchored scan as the map then
// had it.
void ScanGraph::add_match_to_map(std::size_t k, const Pose& placed,
                                 const Eigen::Matrix4d& information, const char* origin) {
  if (const auto match = as_found(k, placed, information)) tie_to_map(k, *match, origin);
}

// A map match with the anchored scan nearest to where it placed the scan, as the graph has that
// scan now; nothing while no scan is anchored.
std::optional<ScanGraph::MapCandidate> ScanGraph::as_found(
    std::size_t k, const Pose& placed, const Eigen::Matrix4d& information) const {
  std::optional<std::size_t> nearest;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < graph_.size(); ++j) {
    if (j == k || !anchored_[j]) continue;
    const Pose& p = graph_.pose(j);
    const double d = std::hypot(p.x - placed.x, p.y - placed.y);
    if (d < best) best = d, nearest = j;
  }
  if (!nearest) return std::nullopt;
  return MapCandidate{placed, information, *nearest, graph_.pose(*nearest)};
}

// Where a map match puts the scan now: the graph may have moved the map since the match.
Pose ScanGraph::placed_now(std::size_t k, const MapCandidate& c) const {
  const Pose& at = graph_.pose(k);
  return compose(graph_.pose(c.reference), relative_pose(c.reference_pose, c.placed), at.roll,
                 at.pitch);
}

// Where scan k likeliest lies: where its map match waiting for confirmation puts it, else where
// the graph has it. A match waits because it moved the scan farther than the odometry usually
// errs; a pair searched from the odometry's estimate would then end beyond max_search_shift_m,
// and a scan matched right (2.7 cm) stayed out of the map, 7 m off, although later scans saw
// what it saw (issue 17). A pair with an anchored scan believes the match only where it agrees
// (later_pair_confirms).
Pose ScanGraph::likeliest(std::size_t k) const {
  return pending_map_[k] ? placed_now(k, *pending_map_[k]) : graph_.pose(k);
}

void ScanGraph::tie_to_map(std::size_t k, const MapCandidate& c, const char* origin) {
  graph_.set_pose(k, placed_now(k, c));  // a levelled match keeps the measured tilt
  anchored_[k] = 1;
  uncertain_[k] = MoveUncertainty{};
  add_match_edge({c.reference, k, relative_pose(c.reference_pose, c.placed),
                  match_information(turned_information(c.information, c.reference_pose.yaw),
                                    config_.match_sigma_m),
                  EdgeKind::kMatch},
                 origin, k);
  pending_[k].clear();
}

void ScanGraph::match_pairs(std::size_t k, bool matched_to_map, GraphUpdate& update) {
  const Pose& at = graph_.pose(k);
  std::vector<std::pair<double, std::size_t>> near;
  for (std::size_t j = 0; j < k; ++j) {
    // The map match already related the scan to every anchored scan around it, and more
    // accurately than one scan can (more overlap): pairs with those would only add noisier,
    // correlated copies of it, which bend the graph (a 1 cm sideways error 25 m away turns a
    // scan by 0.02°). A scan the map does not hold yet is what a pair can tie in.
    if (matched_to_map && anchored_[j]) continue;
    const Pose p = likeliest(j);
    const double d = std::hypot(p.x - at.x, p.y - at.y);
    if (d <= config_.pair_radius_m) near.emplace_back(d, j);
  }
  std::sort(near.begin(), near.end());
  if (near.size() > config_.max_pairs) near.resize(config_.max_pairs);
  const auto t0 = std::chrono::steady_clock::now();
  // Each pair starts from the graph as the pairs before it left it (a scan tied in by two
  // agreeing pairs is searched narrowly from there on); matched ahead where that holds.
  detail::match_ahead_of_turn(
      near.size(), config_.threads, [&](std::size_t n) { return pair_start(near[n].second, k); },
      [&](std::size_t n, const PairStart& start) { return match_pair(near[n].second, k, start); },
      [&](std::size_t n, const std::optional<GraphEdge>& edge) {
        const std::size_t j = near[n].second;
        ++update.pairs_tried;
        if (!edge) return;
        ++update.pairs_matched;
        if (anchored_[j] == anchored_[k]) {
          // Two scans neither of which the map holds: their chain floats together until one is
          // tied in (anchors nothing).
          add_match_edge(*edge, "pair-search", kNoNode);
        } else {
          offer(*edge, anchored_[j] ? k : j);
        }
      });
  update.match_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// How far off the graph's estimate of `to` seen from `from` may be: a robot's consecutive scans
// by the move alone (odometry is good over one move, whatever came before), others by what
// each end's own estimate may be off.
MoveUncertainty ScanGraph::relative_uncertainty(std::size_t from, std::size_t to) const {
  if (previous_[to] == from)
    return odometry_uncertainty(relative_pose(reported_[from], reported_[to]), driven_[to]);
  const MoveUncertainty& f = uncertain_[from];
  const MoveUncertainty& t = uncertain_[to];
  return {std::hypot(f.xy_m, t.xy_m), std::hypot(f.z_m, t.z_m), std::hypot(f.yaw_deg, t.yaw_deg)};
}

ScanGraph::PairStart ScanGraph::pair_start(std::size_t from, std::size_t to) const {
  return {level(likeliest(from)), level(likeliest(to)), relative_uncertainty(from, to)};
}

std::optional<GraphEdge> ScanGraph::match_pair(std::size_t from, std::size_t to,
                                               const PairStart& start) const {
  const Pose& a = start.from;
  const Pose& b = start.to;
  const Eigen::Isometry3d initial = a.isometry().inverse() * b.isometry();
  // One end is not anchored (match_pairs): where it lies may be metres off.
  const RegistrationResult r = register_scans(
      *thinned_[from], *thinned_[to], initial, Method::kSearchGicp,
      widened(config_.registration, start.uncertainty), {scanners_[from], scanners_[to]});
  if (!r.converged) return std::nullopt;
  // How far the result is from where the graph had the pair, in `from`'s levelled frame (the
  // clouds are levelled: the transform is the relative pose itself).
  const RelativePose was = relative_pose(a, b), now = relative_pose(a, r.transform);
  const double shift = std::hypot(now.x - was.x, now.y - was.y, now.z - was.z);
  const double turn = std::abs(rad2deg(std::remainder(now.yaw - was.yaw, 2 * M_PI)));
  if (shift > config_.max_search_shift_m || turn > config_.max_search_turn_deg) {
    return std::nullopt;
  }
  return GraphEdge{from, to, now, match_information(r.information, config_.pair_sigma_m),
                   EdgeKind::kMatch};
}

void ScanGraph::update_anchors(const GraphSolveReport& solve) {
  const std::vector<std::uint8_t> outlier = outlier_flags(graph_.edges().size(), solve);
  std::fill(anchored_.begin(), anchored_.end(), 0);
  anchored_[0] = 1;
  for (std::size_t e = 0; e < graph_.edges().size(); ++e) {
    if (anchors_[e] != kNoNode && !outlier[e]) anchored_[anchors_[e]] = 1;
  }
  for (std::size_t i = 0; i < anchored_.size(); ++i) {
    if (anchored_[i]) uncertain_[i] = MoveUncertainty{};
  }
}

void ScanGraph::anchor_by_sensors(std::size_t k, std::size_t from,
                                  const Eigen::Matrix4d& information) {
  // Trusted like odometry (no robust loss): the sensors were judged good enough to place it.
  add_match_edge({from, k, relative_pose(reported_.at(from), reported_.at(k)), information,
                  EdgeKind::kOdometry},
                 "sensors", k);
  anchored_[k] = 1;
  uncertain_[k] = MoveUncertainty{};
  pending_[k].clear();
}

void ScanGraph::add_match_edge(const GraphEdge& edge, const char* origin, std::size_t anchors) {
  graph_.add_edge(edge);
  origins_.emplace_back(origin);
  anchors_.push_back(anchors);
}

// Where `edge` puts its end `scan` from the other end's current estimate.
Pose ScanGraph::implied(const GraphEdge& edge, std::size_t scan) const {
  const Pose& at = graph_.pose(scan);
  if (scan == edge.to) return compose(graph_.pose(edge.from), edge.measured, at.roll, at.pitch);
  Pose relative;
  relative.x = edge.measured.x;
  relative.y = edge.measured.y;
  relative.z = edge.measured.z;
  relative.yaw = edge.measured.yaw;
  Pose from =
      Pose::from_isometry(level(graph_.pose(edge.to)).isometry() * relative.isometry().inverse());
  from.roll = at.roll;
  from.pitch = at.pitch;
  return from;
}

// A pairwise match with an anchored scan ties `scan` in only when a second one, with another
// anchored scan, puts it in the same place: one match found in a repeated structure (the far
// face of a building as deep as the search is wide) would otherwise bring a scan into the map
// metres off, and the map never recovers from a phantom wall. Until then the result waits.
void ScanGraph::offer(const GraphEdge& edge, std::size_t scan) {
  if (later_pair_confirms(scan, edge)) {
    believe_waiting(scan);
    add_match_edge(edge, "pair-search", scan);
    return;
  }
  const Pose there = implied(edge, scan);
  std::vector<GraphEdge>& waiting = pending_[scan];
  std::vector<GraphEdge> agreeing;
  for (const GraphEdge& other : waiting) {
    const std::size_t other_end = other.from == scan ? other.to : other.from;
    const std::size_t this_end = edge.from == scan ? edge.to : edge.from;
    if (other_end == this_end) continue;
    if (agree(implied(other, scan), there)) agreeing.push_back(other);
  }
  if (agreeing.empty()) {
    waiting.push_back(edge);
    return;
  }
  graph_.set_pose(scan, there);
  anchored_[scan] = 1;
  uncertain_[scan] = MoveUncertainty{};
  add_match_edge(edge, "pair-search", scan);
  for (const GraphEdge& other : agreeing) add_match_edge(other, "pair-search", scan);
  waiting.clear();
}

}  // namespace scanplan

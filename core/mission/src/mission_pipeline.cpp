#include "scanplan/mission/mission_pipeline.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "scanplan/mission/ahead_of_turn.hpp"
#include "scanplan/registration/alignment_quality.hpp"

namespace scanplan {
namespace {

// A move smaller than this is not worth telling anyone about (the range noise is 1 cm).
constexpr double kNoticeableM = 0.005;
constexpr double kNoticeableDeg = 0.01;

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// `config` searching as far as the pose it starts from may be off (ScanGraph's uncertainty), and
// correcting as far as the widest search and GICP after it reach. A correction beyond the pose
// sensors' usual reach, or one from a pose that may be off by more, is not applied as it stands
// (unsure(); ScanGraph::add's `tentative`): on the campus, applied at once, such corrections
// were right 11 times and wrong twice, each time by one building's depth (16 m), and a scan
// placed inside a building ends the mission. Refused instead, a robot lost by more than its
// odometry's 3σ stayed lost: its every match right, and every one refused (issue 17).
// `correct_as_far` false keeps the sensors' own limit.
MapMatchConfig widened(MapMatchConfig config, const MoveUncertainty& prior,
                       bool correct_as_far = true) {
  config.registration = widened(config.registration, prior);
  if (!correct_as_far) return config;
  config.max_correction_m =
      std::max(config.max_correction_m, 1.5 * std::sqrt(2.0) * kWidestSearchM);
  config.max_correction_deg = std::max(config.max_correction_deg, kWidestSearchDeg + 10);
  return config;
}

// The pipeline's region thresholds are the planner's: one set, changed by the operator.
PipelineConfig with_planner_thresholds(PipelineConfig mapping, const PlannerConfig& planner) {
  mapping.regions = planner.regions;
  mapping.movable = planner.movable;
  return mapping;
}

// The map match's configuration for `scan`: its lengths sized by the scan once, here, so that
// the map's points can be gathered as thinly as the match will use them (points_of).
MapMatchConfig sized_for(MapMatchConfig config, const PointCloud& scan) {
  config.registration = adapted_config(scan, config.registration);
  config.registration.adapt_to_scene = false;
  return config;
}

}  // namespace

MissionPipeline::MissionPipeline(MissionConfig config)
    : config_(std::move(config)),
      mapping_(with_planner_thresholds(config_.mapping, config_.planner)),
      sensor_frame_(config_.pose_noise) {
  if (config_.matching && config_.graph) {
    graph_.emplace(*config_.graph, config_.pose_noise);
  } else if (config_.matching) {
    anchored_map_.emplace(config_.mapping.mls);
  }
}

Pose MissionPipeline::prior(const Pose& reported, const std::string& track) const {
  if (graph_ && config_.pose_noise.model == OdometryModel::kDrift) {
    if (const auto last = graph_->last_anchored_of(track)) {
      // Odometry is good over one move and bad over a mission: carry the moves since the
      // robot's latest scan the map could place, not the frame.
      return compose(graph_->poses()[*last], relative_pose(graph_->reported(*last), reported),
                     reported.roll, reported.pitch);
    }
  }
  return sensor_frame_.to_map(reported);
}

bool MissionPipeline::has_map() const {
  return mapping_.regions() && mapping_.movable() && mapping_.target();
}

std::optional<MissionPipeline::MatchInput> MissionPipeline::match_input(const PointCloud& scan,
                                                                        const Pose& reported,
                                                                        const std::string& track,
                                                                        double driven_m) const {
  if (!config_.matching || placed_.empty()) return std::nullopt;
  const Pose start = prior(reported, track);
  MapMatchConfig config = *config_.matching;
  if (graph_) {
    if (const auto prior = graph_->prior_uncertainty(track, reported, driven_m)) {
      config = widened(config, *prior);
    }
  }
  MatchInput in{{}, sized_for(config, scan), start, {{}, scanner_view()}};
  in.map_points =
      points_of(match_sources(start.x, start.y, config.target_radius_m), start.x, start.y,
                config.target_radius_m, &in.views.target, in.config.registration.voxel_m);
  return in;
}

std::optional<MapMatch> MissionPipeline::place(const PointCloud& scan, const Pose& reported,
                                               const std::string& track, double driven_m) const {
  const std::optional<MatchInput> in = match_input(scan, reported, track, driven_m);
  if (!in) return std::nullopt;
  return match_to_map(in->map_points, scan, in->prior, in->config, in->views);
}

std::shared_ptr<const PointCloud> MissionPipeline::to_map_frame(const PointCloud& scan,
                                                                const Pose& placed) {
  const Eigen::Affine3f map_from_scan = placed.isometry().cast<float>();
  PointCloud in_map;
  in_map.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    in_map.push_back(map_from_scan * scan.points[i],
                     scan.has_colors() ? scan.colors[i] : Rgb{128, 128, 128});
  }
  return std::make_shared<const PointCloud>(std::move(in_map));
}

std::shared_ptr<const PointCloud> MissionPipeline::add(const PointCloud& scan,
                                                       const Placement& where) {
  add(scan, where, to_map_frame(scan, where.placed));
  return placed_.back();
}

void MissionPipeline::add(const PointCloud& scan, const Placement& where,
                          std::shared_ptr<const PointCloud> in_map) {
  const bool anchored = placed_.empty() || where.matched;
  anchored_.push_back(anchored ? 1 : 0);
  cloud_bounds_.push_back(bounds_of(*in_map));
  placed_.push_back(std::move(in_map));
  reported_.push_back(where.reported);
  poses_.push_back(where.placed);
  cloud_poses_.push_back(where.placed);
  map_poses_.push_back(where.placed);
  anchored_near_.push_back(0);
  in_map_.push_back(0);
  goals_.push_back(where.goal);
  if (!graph_) {
    join_map(placed_.size() - 1);
    return;
  }
  const std::vector<Pose> before = poses_;
  const auto t0 = Clock::now();
  const std::optional<SensorFix> fix = where.matched ? std::nullopt : sensors_place(where);
  if (config_.pose_noise.model == OdometryModel::kAbsolute) graph_->set_sensor_frame(sensor_frame_);
  GraphUpdate update = graph_->add(scan, where, where.matched && unsure(where), scanner_view());
  const std::size_t k = placed_.size() - 1;
  if (fix && !graph_->anchored(k)) {
    graph_->anchor_by_sensors(k, fix->from, fix->information);
    update.solve = graph_->solve();
  }
  const auto t1 = Clock::now();
  follow_graph();
  const auto t2 = Clock::now();
  const bool rematched = rematch_refused(update);
  const auto t3 = Clock::now();
  if (rematched) follow_graph();
  last_correction_ = correction(update, before);
  last_correction_->graph_ms = ms_between(t0, t1) + ms_between(t2, t3);
}

std::string MissionPipeline::outside_reason(std::size_t i) const {
  if (in_map(i)) return "";
  const std::string why = graph_ ? graph_->outside_reason(i) : "";
  // Anchored but not yet joined: the map takes it with the next update.
  return why.empty() ? "it joins the map with its next update" : why;
}

// The map holds the scan where the graph has it, its points moved there on the way in; after
// every scan already in it, whenever it was taken (map_order()).
void MissionPipeline::join_map(std::size_t i) {
  map_order_.push_back(i);
  map_poses_[i] = poses_[i];
  mapping_.add_placed_scan(*placed_[i], cloud_poses_[i], map_poses_[i]);
  in_map_[i] = 1;
  if (anchored_[i]) {
    sensor_frame_.add(reported_[i], poses_[i]);
    if (anchored_map_) {
      anchored_map_->insert_placed_scan(*placed_[i], cloud_poses_[i].isometry(),
                                        map_poses_[i].isometry(),
                                        Eigen::Vector3d(0, 0, config_.mapping.sensor_height_m));
    }
  }
}

// A scan no match placed joins the map all the same where the pose sensors place it within the
// accuracy the map is built to (3σ within kSensorsPlaceM / _Deg): an exact simulation, a total
// station, or a drive of a few decimetres on odometry from a placed scan. Anywhere else it
// waits for a match: a scan placed metres off makes phantom walls and steps.
std::optional<MissionPipeline::SensorFix> MissionPipeline::sensors_place(
    const Placement& where) const {
  if (placed_.size() <= 1) return std::nullopt;  // the first scan is the map frame
  const PoseNoise& noise = config_.pose_noise;
  MoveUncertainty u;
  std::size_t from = 0;
  if (noise.model == OdometryModel::kAbsolute) {
    // Two independent fixes: the first scan's and this one's.
    u = {std::sqrt(2.0) * noise.xy_sigma_m, std::sqrt(2.0) * noise.z_sigma_m,
         std::sqrt(2.0) * noise.yaw_sigma_deg};
  } else {
    const auto last = graph_->last_anchored_of(where.track);
    const auto prior = graph_->prior_uncertainty(where.track, where.reported, where.driven_m);
    if (!last || !prior) return std::nullopt;
    u = *prior;
    from = *last;
  }
  if (3 * u.xy_m > kSensorsPlaceM || 3 * u.yaw_deg > kSensorsPlaceDeg) return std::nullopt;
  // σ never below what the scanner itself resolves: an exact simulation is no infinitely sure
  // edge.
  const double xy = std::max(u.xy_m, 0.005), z = std::max(u.z_m, 0.005);
  const double yaw = deg2rad(std::max(u.yaw_deg, 0.01));
  const Eigen::Vector4d sigma(xy, xy, z, yaw);
  return SensorFix{from, sigma.cwiseAbs2().cwiseInverse().asDiagonal()};
}

// Whether a match is to wait for confirmation (ScanGraph::offer_match_to_map): it moved the scan
// from where matching started farther than the pose sensors usually err
// (MapMatchConfig::max_correction_m / _deg), which the search reached only because the robot
// drove far since its last anchored scan (match_input), or it started from a pose that may be
// off by more than that.
bool MissionPipeline::unsure(const Placement& where) const {
  const PoseChange d = pose_change(prior(where.reported, where.track), where.placed);
  const std::optional<MoveUncertainty> u =
      graph_->prior_uncertainty(where.track, where.reported, where.driven_m);
  return d.metres > config_.matching->max_correction_m ||
         d.degrees > config_.matching->max_correction_deg || (u && beyond_reach(*u));
}

// Whether a pose so uncertain may be off by more than the sensors usually err: a match found
// within that reach of it may still be a look-alike of the true place (on the campus, 24 m off
// with a correction of under 6 m, after a robot had lost its anchoring for a dozen scans).
bool MissionPipeline::beyond_reach(const MoveUncertainty& u) const {
  return 3 * std::sqrt(2.0) * u.xy_m > config_.matching->max_correction_m ||
         3 * u.yaw_deg > config_.matching->max_correction_deg;
}
// A scan the map matcher refused when it came may match once more of the map is anchored
// around it: the scans after it fill in what it overlaps with (issue 15's refusals were mostly
// scans with too little anchored in view).
bool MissionPipeline::rematch_refused(GraphUpdate& update) {
  const double radius = config_.matching->target_radius_m;
  struct Retry {
    std::size_t scan;
    std::vector<std::size_t> sources;
  };
  std::vector<Retry> retries;
  for (std::size_t u = 0; u + 1 < placed_.size(); ++u) {  // the newest was matched just now
    if (anchored_[u]) continue;
    const Pose& at = poses_[u];
    std::vector<std::size_t> sources = match_sources(at.x, at.y, radius);
    // Only places scanned anew count: a scan taken again where one was changes nothing the
    // match would see (match_sources), and retrying every refused scan near it at each pass of
    // a long mission made one scan cost seconds.
    const auto near =
        static_cast<std::size_t>(std::count_if(sources.begin(), sources.end(), [&](std::size_t j) {
          return std::hypot(poses_[j].x - at.x, poses_[j].y - at.y) <= radius;
        }));
    if (near <= anchored_near_[u]) continue;
    anchored_near_[u] = near;
    ++update.rematches_tried;
    retries.push_back({u, std::move(sources)});
  }
  bool any = false;
  // A re-match believed may tie in the robot's next scan (ScanGraph::offer_match_to_map), whose
  // own re-match then searches from its new uncertainty: matched ahead where that holds.
  detail::match_ahead_of_turn(
      retries.size(), config_.graph->threads,
      [&](std::size_t r) { return graph_->uncertainty(retries[r].scan); },
      [&](std::size_t r, const MoveUncertainty& uncertain) {
        const Pose& at = poses_[retries[r].scan];
        const PointCloud& scan = graph_->thinned(retries[r].scan);
        const MapMatchConfig config = sized_for(widened(*config_.matching, uncertain), scan);
        MatchViews views{{}, scanner_view()};
        const PointCloud around = points_of(retries[r].sources, at.x, at.y, radius, &views.target,
                                            config.registration.voxel_m);
        return match_to_map(around, scan, level(at), config, views);
      },
      [&](std::size_t r, const MapMatch& m) {
        const std::size_t u = retries[r].scan;
        if (!m.applied) return;
        if (beyond_reach(graph_->uncertainty(u)) ||
            pose_change(poses_[u], m.placed).metres > config_.matching->max_correction_m) {
          graph_->offer_match_to_map(u, m.placed, m.information);
        } else {
          graph_->add_match_to_map(u, m.placed, m.information);
        }
        ++update.rematched;
        any = true;
      });
  if (any) update.solve = graph_->solve();
  return any;
}

MapCorrection MissionPipeline::correction(const GraphUpdate& update,
                                          const std::vector<Pose>& before) const {
  MapCorrection c{update, {}, 0, 0};
  for (std::size_t i = 0; i < before.size(); ++i) {
    const PoseChange d = pose_change(before[i], poses_[i]);
    if (d.metres > kNoticeableM || d.degrees > kNoticeableDeg) c.moved.push_back(i);
    c.max_moved_m = std::max(c.max_moved_m, d.metres);
    c.max_turned_deg = std::max(c.max_turned_deg, d.degrees);
  }
  return c;
}

// The map follows the graph: the anchored scans are in it, near the graph's poses. Each scan's
// points follow past replace_m / _deg; the MLS map is made anew where a scan in it moved past
// remap_m / _deg or lost its anchoring; scans anchored now, the newest or older ones, join it.
void MissionPipeline::follow_graph() {
  poses_ = graph_->poses();
  bool remap = false;
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    anchored_[i] = graph_->anchored(i) ? 1 : 0;
    if (in_map_[i] && (!anchored_[i] || map_lags(i))) remap = true;
    // The points shown follow the graph wherever the scan is, in the map or not.
    if (cloud_lags(i)) set_cloud(i, std::make_shared<const PointCloud>(at_estimate(i)));
  }
  if (remap) replace();
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    if (anchored_[i] && !in_map_[i]) join_map(i);
  }
}

// A scan's points are made anew in the map frame only when the graph moved it past replace_m /
// _deg, the owner's rule for re-sending its chunk: the owner shares these clouds, and a cloud
// re-placed for every few millimetres was a second copy of the scan wherever the owner kept
// the one it showed (the long session's heap: 417 MB of map-frame points for 259 MB of
// scans). What the graph moved less is applied where the points are used (points_of, at_estimate).
bool MissionPipeline::cloud_lags(std::size_t i) const {
  const PoseChange d = pose_change(cloud_poses_[i], poses_[i]);
  return d.metres > config_.replace_m || d.degrees > config_.replace_deg;
}

// Against where the map holds it, not the graph's previous estimate: small moves add up.
bool MissionPipeline::map_lags(std::size_t i) const {
  const PoseChange d = pose_change(map_poses_[i], poses_[i]);
  return d.metres > config_.remap_m || d.degrees > config_.remap_deg;
}

Eigen::Affine3f MissionPipeline::lag_of(std::size_t i) const {
  return (poses_[i].isometry() * cloud_poses_[i].isometry().inverse()).cast<float>();
}

PointCloud MissionPipeline::at_estimate(std::size_t i) const {
  PointCloud out = *placed_.at(i);
  const Eigen::Affine3f lag = lag_of(i);
  for (auto& p : out.points) p = lag * p;
  return out;
}

// The scan as the MLS map holds it: its points moved from where they were placed to its map
// pose, and their bounds there.
MappingPipeline::PlacedScan MissionPipeline::as_mapped(std::size_t i) const {
  MappingPipeline::PlacedScan s{placed_[i].get(), cloud_poses_[i], map_poses_[i], cloud_bounds_[i]};
  if (cloud_poses_[i].isometry().matrix() == map_poses_[i].isometry().matrix()) return s;
  const Eigen::Isometry3f lag =
      (map_poses_[i].isometry() * cloud_poses_[i].isometry().inverse()).cast<float>();
  const Bounds3& b = cloud_bounds_[i];
  s.bounds = Bounds3{};
  for (int corner = 0; corner < 8; ++corner) {
    s.bounds.extend(lag * Eigen::Vector3f(corner & 1 ? b.max.x() : b.min.x(),
                                          corner & 2 ? b.max.y() : b.min.y(),
                                          corner & 4 ? b.max.z() : b.min.z()));
  }
  return s;
}

// The MLS map made anew where scans in it moved past remap_m / _deg or left it: where they lay
// and where they now lie (at the graph's estimate); the rest of it stands
// (MappingPipeline::replace_scans). Only with the graph, whose map is the anchored one (no
// anchored_map_ of its own).
void MissionPipeline::replace() {
  std::vector<Bounds3> changed;
  std::vector<MappingPipeline::PlacedScan> stay;
  std::vector<std::size_t> order;
  std::vector<Pose> reported, placed;
  for (const std::size_t i : map_order_) {
    const bool left = !anchored_[i], moved = !left && map_lags(i);
    if (left || moved) changed.push_back(as_mapped(i).bounds);  // where it lay
    if (left) {
      in_map_[i] = 0;
      continue;
    }
    if (moved) map_poses_[i] = poses_[i];
    stay.push_back(as_mapped(i));
    if (moved) changed.push_back(stay.back().bounds);  // where it lies
    order.push_back(i);
    reported.push_back(reported_[i]);
    placed.push_back(poses_[i]);
  }
  map_order_ = std::move(order);
  mapping_.replace_scans(stay, changed);
  sensor_frame_ = SensorFrame(config_.pose_noise, std::move(reported), std::move(placed));
}

std::vector<FleetPlan> MissionPipeline::plan(const std::vector<FleetRobot>& robots,
                                             std::vector<Eigen::Vector3d> claimed) const {
  if (!has_map()) return {};
  for (const Eigen::Vector3d& p : unplaced_scan_points()) claimed.push_back(p);
  std::vector<FleetRobot> drifting = robots;
  for (FleetRobot& r : drifting) {
    r.drift = drift_of(r.id);
    r.memo = memos_->of(r.id);
  }
  std::vector<FleetPlan> plans =
      plan_fleet(mapping_.map(), *mapping_.target(), mapping_.scan_points(), drifting,
                 std::move(claimed), planner_config(), anchored_map());
  // Each robot's own ranking; the fleet's order of decision stays the forecast's.
  for (FleetPlan& p : plans) check_plan(p.plan);
  return plans;
}

std::optional<DriveDrift> MissionPipeline::drift_of(const std::string& track) const {
  if (!graph_ || config_.pose_noise.model != OdometryModel::kDrift) return std::nullopt;
  const auto latest = graph_->last_of(track);
  if (!latest) return std::nullopt;
  DriveDrift d;
  d.xy_per_m = config_.pose_noise.xy_drift_fraction;
  d.yaw_deg_per_m = config_.pose_noise.yaw_drift_deg_per_10m / 10;
  if (!graph_->anchored(*latest)) {
    if (const auto u = graph_->prior_uncertainty(track, graph_->reported(*latest))) {
      d.start_xy_m = u->xy_m;
      d.start_yaw_deg = u->yaw_deg;
    }
  }
  return d;
}

// Where the scans the map does not hold were taken, as the graph has them: the planner counts
// what they saw as scanned and sends no robot right back there (a scan taken again where one
// could not be placed would most likely fail the same way); a scan around them later ties them
// in. Roughly placed, but metres matter little to that; and where the robot was sent for it,
// too: a lost robot's estimate lies tens of metres off, and without its goal claimed the same
// candidate stayed the best, the robot scanning one spot for the rest of the mission (issue 17,
// seed 1).
std::vector<Eigen::Vector3d> MissionPipeline::unplaced_scan_points() const {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    if (in_map_[i]) continue;
    out.emplace_back(poses_[i].x, poses_[i].y, poses_[i].z);
    if (goals_[i]) out.push_back(*goals_[i]);
  }
  return out;
}

Plan MissionPipeline::plan_from(const Eigen::Vector3d& robot, std::uint64_t seed,
                                const std::string& track) const {
  if (!has_map()) return {};
  PlannerConfig planner = planner_config();
  planner.seed = seed;
  const std::vector<Eigen::Vector2d> points = mapping_.scan_points();
  PlanInput in{mapping_.map(), *mapping_.target(), points, robot};
  in.anchored = anchored_map();
  const std::vector<Eigen::Vector3d> unplaced = unplaced_scan_points();
  if (!unplaced.empty()) in.claimed = &unplaced;
  const std::optional<DriveDrift> drift = drift_of(track);
  if (drift) in.drift = &*drift;
  in.memo = memos_->of(track);
  Plan plan = plan_next_scan(in, planner);
  check_plan(plan);
  return plan;
}

void MissionPipeline::check_plan(Plan& plan) const {
  if (!config_.matching || !config_.planner.registrability.enabled) return;
  const auto t0 = Clock::now();
  check_views(
      plan, [this](const Candidate& c) { return predicted_constraint(c); }, config_.view_check,
      config_.planner.registrability.floor_share);
  plan.plan_ms += ms_between(t0, Clock::now());
}

// The anchored scans' points a match there would be made against (match_input), those a scanner
// there sees, judged in the levelled frame at the candidate as match_to_map judges a match.
double MissionPipeline::predicted_constraint(const Candidate& candidate) const {
  const MapMatchConfig& m = *config_.matching;
  const Eigen::Vector3d& at = candidate.position;
  const double voxel = m.registration.voxel_m;
  Viewpoints views;
  const PointCloud map = points_of(match_sources(at.x(), at.y(), m.target_radius_m), at.x(), at.y(),
                                   m.target_radius_m, &views, voxel);
  // Judged in the candidate's frame, as match_to_map judges a match: one k-d tree over the map
  // gives the view check its surface normals and then weighs what is seen.
  const Eigen::Vector3f floor = at.cast<float>();
  PointCloud target;
  target.points.reserve(map.size());
  for (const Eigen::Vector3f& p : map.points) target.points.push_back(p - floor);
  const AlignmentJudge judge(target);
  const PointCloud seen = visible_points(
      target, scanner_view().origins.front(), voxel, m.target_radius_m, config_.view_check,
      views.transformed(Eigen::Isometry3f(Eigen::Translation3f(-floor))), &judge);
  if (seen.empty()) return 0;
  // Every third point, as the matcher's judge first weighs its results: the weakest constraint
  // is a share of the points, and the normals cost most of the check.
  PointCloud source;
  source.points.reserve(seen.size() / 3 + 1);
  for (std::size_t i = 0; i < seen.size(); i += 3) source.points.push_back(seen.points[i]);
  const RegistrationConfig& r = m.registration;
  return judge
      .evaluate(source, Eigen::Isometry3d::Identity(), r.dof, r.score_max_distance_m,
                r.inlier_distance_m)
      .weakest_constraint;
}

// Too rough to place a scan by themselves: as sensors_place judges it.
PlannerConfig MissionPipeline::planner_config() const {
  PlannerConfig planner = config_.planner;
  const PoseNoise& noise = config_.pose_noise;
  const double fix_xy = std::sqrt(2.0) * noise.xy_sigma_m;
  const double fix_deg = std::sqrt(2.0) * noise.yaw_sigma_deg;
  if (config_.matching && noise.model == OdometryModel::kAbsolute &&
      (3 * fix_xy > kSensorsPlaceM || 3 * fix_deg > kSensorsPlaceDeg)) {
    planner.registrability.min_pose_fixing *= planner.registrability.absolute_fix_factor;
  }
  return planner;
}

GainMemo* MissionPipeline::Memos::of(const std::string& robot) {
  std::lock_guard lock(mutex);
  auto& memo = by_robot[robot];
  if (!memo) memo = std::make_unique<GainMemo>();
  return memo.get();
}

void MissionPipeline::set_planner(const PlannerConfig& planner) {
  config_.planner = planner;
  mapping_.set_region_configs(planner.regions, planner.movable);
}

void MissionPipeline::set_target(TargetRegion target) {
  mapping_.set_target(std::move(target));
}

PointCloud MissionPipeline::points_near(double x, double y, double radius_m, bool anchored_only,
                                        Viewpoints* views) const {
  std::vector<std::size_t> scans;
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    if ((!anchored_only || anchored_[i]) && reaches(i, x, y, radius_m)) scans.push_back(i);
  }
  return points_of(scans, x, y, radius_m, views);
}

bool MissionPipeline::reaches(std::size_t i, double x, double y, double radius_m) const {
  const Bounds3& b = cloud_bounds_[i];
  if (!b.valid()) return false;
  const double dx = std::max({b.min.x() - x, 0.0, x - b.max.x()});
  const double dy = std::max({b.min.y() - y, 0.0, y - b.max.y()});
  return dx * dx + dy * dy <= radius_m * radius_m;
}

// The anchored scans a match near (x, y) is made against: those with points within `radius_m`,
// less each one a later anchored scan was taken within kSameViewM of. A place scanned again
// (a later pass over the site, a second robot) shows the same surfaces from the same spot;
// matched against both, a scan meets every surface twice, and on a long session pass after
// pass the match input grew with the session (200 campus scans: seconds a scan, issue 19).
// The latest scan of a place stays: it shows the scene as it is now.
std::vector<std::size_t> MissionPipeline::match_sources(double x, double y, double radius_m) const {
  std::vector<std::size_t> out;
  std::vector<Eigen::Vector3d> taken;
  for (std::size_t i = placed_.size(); i-- > 0;) {
    if (!anchored_[i] || !reaches(i, x, y, radius_m)) continue;
    const Eigen::Vector3d at(poses_[i].x, poses_[i].y, poses_[i].z);
    if (std::any_of(taken.begin(), taken.end(),
                    [&](const Eigen::Vector3d& t) { return (t - at).norm() < kSameViewM; })) {
      continue;
    }
    taken.push_back(at);
    out.push_back(i);
  }
  std::reverse(out.begin(), out.end());  // in joining order, as the map holds them
  return out;
}

// With `thinned_to_m`, the voxel the caller's match thins the map to: a scan the graph keeps
// thinned to no coarser than that is read from there (ScanGraph::thinned, a fraction of its
// points), the rest at full resolution. On a long session the gathering, cropping and
// thinning of millions of map points had taken 0.5–0.9 s of every match (issue 19).
PointCloud MissionPipeline::points_of(const std::vector<std::size_t>& scans, double x, double y,
                                      double radius_m, Viewpoints* views,
                                      double thinned_to_m) const {
  PointCloud out;
  if (views) *views = {};
  const Eigen::Vector2f c(static_cast<float>(x), static_cast<float>(y));
  const float r2 = static_cast<float>(radius_m * radius_m);
  const Eigen::Vector3f sensor = scanner_view().origins.front();
  // Each scan's points at the graph's estimate (its cloud may lag it by up to replace_m; the
  // graph's thinned copy is levelled at the pose the graph has).
  struct Source {
    const PointCloud* cloud;
    Eigen::Affine3f to_map;
  };
  const auto source = [&](std::size_t i) -> Source {
    if (graph_ && thinned_to_m > 0 && graph_->thinned_voxel_m(i) <= thinned_to_m * (1 + 1e-9)) {
      return {&graph_->thinned(i), Eigen::Affine3f(level(poses_[i]).isometry().cast<float>())};
    }
    return {placed_[i].get(), lag_of(i)};
  };
  const auto within = [&](const Eigen::Affine3f& to_map, const Eigen::Vector3f& p) {
    const Eigen::Vector2f q = to_map.linear().topRows<2>() * p + to_map.translation().head<2>();
    return (q - c).squaredNorm() <= r2;
  };
  // Counted first: millions of points on a long session, and a growing vector would copy them
  // over and over and hold twice their memory while it does.
  std::size_t count = 0;
  for (const std::size_t i : scans) {
    const Source s = source(i);
    for (const auto& p : s.cloud->points) count += within(s.to_map, p) ? 1 : 0;
  }
  out.points.reserve(count);
  if (views) views->origin_of.reserve(count);
  for (const std::size_t i : scans) {
    const std::size_t before = out.size();
    const Source s = source(i);
    for (const auto& p : s.cloud->points) {
      if (within(s.to_map, p)) out.points.push_back(s.to_map * p);
    }
    if (views && out.size() > before) {
      views->origins.push_back(poses_[i].isometry().cast<float>() * sensor);
      views->origin_of.resize(out.size(), static_cast<std::uint32_t>(views->origins.size() - 1));
    }
  }
  return out;
}

void MissionPipeline::set_cloud(std::size_t i, std::shared_ptr<const PointCloud> in_map) {
  cloud_bounds_[i] = bounds_of(*in_map);
  placed_[i] = std::move(in_map);
  cloud_poses_[i] = poses_[i];
}

Viewpoints MissionPipeline::scanner_view() const {
  return Viewpoints::single({0, 0, static_cast<float>(config_.mapping.sensor_height_m)});
}

}  // namespace scanplan

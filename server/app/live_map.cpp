#include "app/live_map.hpp"

#include <spdlog/spdlog.h>

#include <malloc.h>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <set>

#include "scanplan/compression/draco_codec.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/top_view.hpp"
#include "scanplan/planning/fleet_planner.hpp"
#include "scanplan/planning/travel_map.hpp"

namespace scanplan::server {

namespace {

using Clock = std::chrono::steady_clock;
double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

// Where a stored scan joins the mission: its match (if believed) with the match's information,
// on its robot's track, and where the robot was sent for it.
Placement placement_of(const StoredScan& scan) {
  Placement where(scan.estimated, scan.placed, scan.match && scan.match->applied);
  if (scan.match) where.information = scan.match->information;
  where.track = scan.robot;
  where.goal = scan.goal;
  where.driven_m = scan.goal_drive_m;
  return where;
}

}  // namespace

LiveMap::LiveMap(PlanBook& plans, MissionConfig config)
    : mission_(std::move(config)),
      sensor_height_m_(mission_.config().mapping.sensor_height_m),
      plans_(plans),
      claim_separation_m_(mission_.planner().claim_separation_m),
      encoder_([this] { encode_loop(); }) {}

LiveMap::~LiveMap() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  encode_wanted_.notify_all();
  encoder_.join();
}

void LiveMap::encode_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    encode_wanted_.wait(lock, [&] {
      return stopping_ || (encoded_generation_ != generation_ && encode_waiters_ > 0);
    });
    if (stopping_) return;
    std::vector<std::shared_ptr<const PointCloud>> parts;
    for (std::size_t i = 0; i < placed_.size(); ++i) {
      if (in_map_[i]) parts.push_back(placed_[i]);
    }
    const std::int64_t last = scans_.empty() ? 0 : scans_.back().id;
    const std::uint64_t generation = generation_;
    lock.unlock();
    std::shared_ptr<const std::string> encoded;
    try {
      // Straight from the scans' clouds: a copy of the whole map first was 15 bytes a point
      // more at the encoding's peak.
      std::vector<const PointCloud*> clouds;
      std::size_t count = 0;
      for (const auto& p : parts) {
        clouds.push_back(p.get());
        count += p->size();
      }
      if (count > 0) encoded = std::make_shared<const std::string>(encode_draco(clouds));
      parts.clear();
      // Draco's working memory is hundreds of megabytes at millions of points, freed by now
      // but kept by the allocator: handed back, the laptop's other programs get it (the next
      // scan's match faults its pages in again; within the benchmarks' spread).
      malloc_trim(0);
    } catch (const std::exception&) {
      // Out of memory or a Draco failure: the previous encoding stays; readers see its
      // last_scan and can fetch the rest with ?since.
      lock.lock();
      encoded_last_scan_ = last;
      encoded_generation_ = generation;
      encoded_changed_.notify_all();
      continue;
    }
    lock.lock();
    encoded_ = std::move(encoded);
    encoded_last_scan_ = last;
    encoded_generation_ = generation;
    encoded_changed_.notify_all();
  }
}

const std::vector<std::string>& LiveMap::layer_names() {
  static const std::vector<std::string> kNames = {"regions", "elevation", "movable"};
  return kNames;
}

std::optional<MapMatch> LiveMap::place(const PointCloud& scan, const Pose& reported,
                                       const std::string& robot, double driven_m) const {
  // Only the copy of the map's points near the scan under the lock: the match itself takes
  // hundreds of milliseconds, and parameter changes and goals must not wait for it.
  std::optional<MissionPipeline::MatchInput> in;
  {
    std::lock_guard encode_lock(encode_mutex_);
    in = mission_.match_input(scan, reported, robot, driven_m);
  }
  if (!in) return std::nullopt;
  return match_to_map(in->map_points, scan, in->prior, in->config, in->views);
}

LiveMap::Added LiveMap::add(const StoredScan& scan, const PointCloud& cloud) {
  // The scan in the map frame first: should it fail (out of memory), nothing of the scan has
  // reached the map yet. Its Draco chunk (~25 ms for a campus scan) is made when first asked
  // for (encoded_chunk), after the plan has gone out: the operator waits for the candidates.
  std::shared_ptr<const PointCloud> shared = MissionPipeline::to_map_frame(cloud, scan.placed);
  // Writers take turns on encode_mutex_; readers only wait for the short commit below, and
  // they see the scan, its points and the plan that includes it appear together.
  std::lock_guard encode_lock(encode_mutex_);
  const auto join_start = Clock::now();
  mission_.add(cloud, placement_of(scan), shared);
  const double join_ms = ms_between(join_start, Clock::now());
  // Only writers change the scans, under encode_mutex_ (held): read without mutex_.
  std::vector<StoredScan> scans = scans_;
  std::vector<std::shared_ptr<const PointCloud>> placed = placed_;
  std::vector<std::uint8_t> in_map = in_map_;
  scans.push_back(scan);
  placed.push_back(shared);
  in_map.push_back(0);
  Followed f = follow_mission(std::move(scans), std::move(placed), std::move(in_map));
  // The thinned map is 0.3 m cubes: made anew when scans join or leave the map or move by a
  // third of a cube (a few seconds' work on a large map), else the new scan is added.
  const MapCorrected& c = f.corrected;
  const auto thin_start = Clock::now();
  rethin(f,
         /*whole=*/!c.joined.empty() || !c.left.empty() || c.max_moved_m > kThinnedMapVoxelM / 3);
  Added out;
  out.times.thin = ms_between(thin_start, Clock::now());
  if (const auto& graph = mission_.last_correction()) out.times.graph = graph->graph_ms;
  out.times.map = join_ms - out.times.graph;
  follow_robots(f);
  last_scan_ = {scan.id, scan.robot};
  // The map changed around the new scan: points a robot refused there may be worth a try again
  // (the completed radius, paper §3.3: what a scan completes).
  if (f.in_map.back()) {
    const Pose& at = f.scans.back().placed;
    plans_.forget_refusals_near(at.x, at.y, mission_.planner().regions.completed_radius_m, scan.id);
  }
  out.corrected = f.corrected;
  out.in_map = f.in_map.back() != 0;
  out.outside = f.outside.back();
  out.plans = refresh_derived([&] { commit(std::move(f)); }, /*scan_joined=*/true, &out.times);
  encode_wanted_.notify_one();
  // Outside mutex_ so readers are not held up, inside encode_mutex_ so maps and plans go out in
  // the order they were made; the map first, as the plan is made from it.
  if (on_map) on_map(thinned_.cloud());
  if (on_plan) {
    for (const PlanRecord& plan : out.plans) on_plan(plan);
  }
  return out;
}

void LiveMap::follow_robots(const Followed& f) {
  // A robot stands where it last scanned; while that scan waits outside the map (metres off,
  // perhaps), it is planned from its latest scan in the map, as the map can place it.
  std::map<std::string, std::pair<Pose, bool>> at;
  for (std::size_t i = 0; i < f.scans.size(); ++i) {
    auto [it, fresh] = at.try_emplace(f.scans[i].robot, f.scans[i].placed, f.in_map[i] != 0);
    if (!fresh && (f.in_map[i] || !it->second.second)) {
      it->second = {f.scans[i].placed, f.in_map[i] != 0};
    }
  }
  for (const auto& [robot, pose] : at) scan_pose_of_[robot] = pose.first;
}

LiveMap::Followed LiveMap::follow_mission(std::vector<StoredScan> scans,
                                          std::vector<std::shared_ptr<const PointCloud>> placed,
                                          std::vector<std::uint8_t> in_map) const {
  Followed f;
  const std::size_t newest = scans.size() - 1;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    const Pose& now = mission_.poses()[i];
    const bool now_in = mission_.in_map(i);
    const bool was_in = in_map[i] != 0;
    // The pipeline makes a scan's points anew only when the graph moved it past replace_m /
    // _deg (MissionPipeline::placed_scans): the map shows the same cloud, never a copy of it.
    const bool moved = placed[i] != mission_.placed_scans()[i];
    const PoseChange d = pose_change(scans[i].placed, mission_.cloud_poses()[i]);
    if (moved) {
      scans[i].placed = mission_.cloud_poses()[i];
      placed[i] = mission_.placed_scans()[i];
      f.unencoded.push_back(scans[i].id);
    }
    in_map[i] = now_in ? 1 : 0;
    f.outside.push_back(mission_.outside_reason(i));
    MapCorrected& c = f.corrected;
    if (i == newest) {
      if (moved || !now_in) c.poses.push_back({scans[i].id, now, now_in});
      continue;
    }
    if (moved && was_in && now_in) {
      c.moved.push_back(scans[i].id);
      c.max_moved_m = std::max(c.max_moved_m, d.metres);
      c.max_turned_deg = std::max(c.max_turned_deg, d.degrees);
    }
    if (now_in && !was_in) c.joined.push_back(scans[i].id);
    if (was_in && !now_in) c.left.push_back(scans[i].id);
    if (moved || now_in != was_in) c.poses.push_back({scans[i].id, scans[i].placed, now_in});
  }
  // Bounds of the points that changed; the others' stay (under encode_mutex_, held by the
  // caller, placed_ changes in no other thread).
  f.bounds = scan_bounds_;
  f.bounds.resize(placed.size());
  for (std::size_t i = 0; i < placed.size(); ++i) {
    if (i >= placed_.size() || placed_[i] != placed[i]) f.bounds[i] = bounds_of(*placed[i]);
  }
  f.scans = std::move(scans);
  f.placed = std::move(placed);
  f.in_map = std::move(in_map);
  return f;
}

void LiveMap::rethin(const Followed& f, bool whole) {
  if (!whole) {
    if (f.in_map.back()) thinned_.add(*f.placed.back());
  } else {
    // The thinned map cannot take a scan out: made anew from the scans in the map.
    VoxelMap thinned{kThinnedMapVoxelM};
    for (std::size_t i = 0; i < f.placed.size(); ++i) {
      if (f.in_map[i]) thinned.add(*f.placed[i]);
    }
    thinned_ = std::move(thinned);
  }
}

void LiveMap::commit(Followed f) {
  for (const std::int64_t id : f.unencoded) chunks_[id] = nullptr;
  scan_bounds_ = std::move(f.bounds);
  scans_ = std::move(f.scans);
  placed_ = std::move(f.placed);
  in_map_ = std::move(f.in_map);
  outside_ = std::move(f.outside);
  point_count_ = 0;
  bounds_ = Bounds3{};
  for (std::size_t i = 0; i < scans_.size(); ++i) {
    if (!in_map_[i]) continue;
    point_count_ += placed_[i]->size();
    if (scan_bounds_[i].valid()) {
      bounds_.extend(scan_bounds_[i].min);
      bounds_.extend(scan_bounds_[i].max);
    }
  }
  ++generation_;
}

namespace {

// The layers' pixels in the map, as top_view_pixel places them.
LayerGeometry geometry_of(const RegionMap& regions) {
  const auto& g = regions.cells;
  const int s = std::max(1, TopViewStyle{}.px_per_cell);
  LayerGeometry geometry;
  geometry.min_x = g.origin.x * g.cell_m;
  geometry.min_y = g.origin.y * g.cell_m;
  geometry.max_x = (g.origin.x + g.cols) * g.cell_m;
  geometry.max_y = (g.origin.y + g.rows) * g.cell_m;
  geometry.px_per_m = s / g.cell_m;
  geometry.width = g.cols * s;
  geometry.height = g.rows * s;
  return geometry;
}

}  // namespace

std::vector<PlanRecord> LiveMap::make_plans() const {
  // Several robots share the map: they are decided one after another (plan_fleet), each
  // counting what the robots before it will scan as taken (PlanInput::claimed), so no two are
  // sent to one spot. A robot driving to an approved goal keeps its plan, and its goal is
  // claimed first.
  std::vector<Eigen::Vector3d> claims;
  const std::map<std::string, Eigen::Vector3d> driving = plans_.driving_goals();
  for (const auto& [robot, goal] : driving) claims.push_back(goal);
  std::vector<FleetRobot> robots;
  for (const auto& [robot, at] : scan_pose_of_) {
    if (!driving.count(robot)) {
      robots.push_back({robot, {at.x, at.y, at.z}, {}, plans_.refused_points(robot)});
    }
  }
  const PlannerConfig& planner = mission_.planner();
  std::vector<PlanRecord> records;
  for (FleetPlan& decided : mission_.plan(robots, std::move(claims))) {
    const Plan& plan = decided.plan;
    if (plan.ranked.empty()) {
      const Pose& at = scan_pose_of_.at(decided.robot);
      spdlog::warn(
          "no candidate for '{}' from ({:.1f}, {:.1f}): movable region {:.0f} m², {:.0f} m² "
          "unscanned and {:.0f} m² low-resolution in the target region",
          decided.robot, at.x, at.y, plan.movable.area_m2(), plan.regions.unscanned_m2(),
          plan.regions.low_resolution_m2());
    }
    PlanRecord record;
    record.id = plans_.new_plan_id();
    record.based_on_scan = last_scan_.first;
    record.robot = decided.robot;
    for (std::size_t k = 0; k < plan.ranked.size(); ++k) {
      CandidateRecord c;
      c.id = plans_.new_candidate_id();
      c.rank = static_cast<int>(k + 1);
      c.candidate = plan.ranked[k];
      record.candidates.push_back(std::move(c));
    }
    record.policy = std::string(policy_name(planner.policy));
    record.alpha = planner.alpha;
    record.plan_ms = plan.plan_ms;
    record.best_gain_m2 = plan.best_gain_m2;
    records.push_back(std::move(record));
  }
  // The robot whose scan came last is the one waiting for a decision: its plan goes last, the
  // newest on the latched DDS topic.
  std::stable_partition(records.begin(), records.end(),
                        [&](const PlanRecord& r) { return r.robot != last_scan_.second; });
  return records;
}

std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> LiveMap::render_layers()
    const {
  const MappingPipeline& mapping = mission_.mapping();
  const RegionMap& regions = *mapping.regions();
  const MovableRegion& movable = *mapping.movable();
  const auto png = [](const cv::Mat& img) {
    return std::make_shared<const std::vector<std::uint8_t>>(encode_png(img));
  };
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> layers;
  // The candidates are not drawn in: clients draw them over the layer (the page does, with
  // their states), and the layer stays the paper's Fig. 4/5.
  layers["regions"] = png(render_regions(regions, &movable, mapping.scan_points()));
  layers["elevation"] = png(render_elevation(mapping.map(), regions));
  layers["movable"] = png(render_movable(mapping.map(), movable, regions));
  return layers;
}

std::vector<PlanRecord> LiveMap::refresh_derived(const std::function<void()>& commit,
                                                 bool scan_joined, AddTimes* times) {
  if (!mission_.has_map()) {
    std::lock_guard lock(mutex_);
    if (commit) commit();
    return {};
  }
  const auto t0 = Clock::now();
  std::vector<PlanRecord> records = make_plans();
  const auto t1 = Clock::now();
  auto layers = render_layers();
  if (times) {
    times->plan = ms_between(t0, t1);
    times->layers = ms_between(t1, Clock::now());
  }
  const RegionMap& regions = *mission_.mapping().regions();
  const auto elevation_m = elevation_range(mission_.mapping().map(), regions);
  const MapAreas areas{regions.completed_m2(), regions.low_resolution_m2(), regions.unscanned_m2(),
                       mission_.mapping().movable()->area_m2()};
  {
    // The scan, its map and everything derived from it appear to readers together.
    std::lock_guard lock(mutex_);
    if (commit) commit();
    plans_.replace(records, last_scan_.second);
    layers_ = std::move(layers);
    layer_geometry_ = geometry_of(regions);
    elevation_range_ = elevation_m;
    areas_ = areas;
    // Only a joining scan has areas "after" it (set_params and rebuild re-segment without one).
    if (commit && scan_joined) areas_after_[last_scan_.first] = areas;
  }
  return records;
}

namespace {

// Where a robot sent to (x, y) would stand, and the drive there from `from`.
struct GoalSite {
  CellIndex cell;
  float floor_z = 0;
  TravelMap travel;
};

// Checks that a robot at `from`, which can reach `movable`, can be sent to (x, y); throws
// GoalRefused naming why not.
GoalSite goal_site(const MappingPipeline& mapping, const PlannerConfig& planner,
                   const MovableRegion& movable, const Eigen::Vector3d& from, double x, double y) {
  const MlsMap& map = mapping.map();
  const TargetRegion& target = *mapping.target();
  char where[64];
  std::snprintf(where, sizeof where, "(%.1f, %.1f)", x, y);
  if (!target.contains(x, y)) {
    throw GoalRefused("outside_target",
                      std::string(where) + " is outside the target region being mapped");
  }
  if (in_any(planner.no_go, {x, y})) {
    throw GoalRefused("no_go", std::string(where) + " lies in a no-go zone");
  }
  const CellIndex cell = map.index_of(x, y);
  if (!map.cell(cell)) {
    throw GoalRefused("no_data", std::string(where) +
                                     " has not been scanned yet: the robot is only sent where "
                                     "the map shows it can drive");
  }
  if (!movable.contains(cell)) {
    char why[200];
    std::snprintf(why, sizeof why,
                  " is not in the movable region: no floor the robot can reach there (a step "
                  "over %.2f m, an obstacle or too little headroom)",
                  planner.movable.max_step_m);
    throw GoalRefused("not_movable", where + std::string(why));
  }
  TravelMap travel = travel_map(map, movable, from, planner.movable,
                                planner.stay_in_target ? &target : nullptr, planner.no_go);
  if (!travel.reachable(cell)) {
    throw GoalRefused("unreachable", std::string(where) +
                                         " is movable but no drive inside the target region "
                                         "(from a robot inside it) and around the no-go zones "
                                         "leads there from the robot");
  }
  const auto offset = movable.patch.offset(cell);
  const float floor_z = map.cell(cell)->patches[movable.patch.values[*offset]].mean_z;
  return {cell, floor_z, std::move(travel)};
}

}  // namespace

CandidateRecord LiveMap::add_goal(double x, double y, const std::string& robot_id) {
  std::lock_guard encode_lock(encode_mutex_);
  if (plans_.empty()) throw GoalRefused("no_map", "there is no map yet: take a first scan");
  const std::string robot = robot_id.empty() ? plans_.latest_robot() : robot_id;
  if (!plans_.plan(robot)) {
    throw GoalRefused("unknown_robot",
                      "robot '" + robot + "' has no plan: it has not sent a scan yet");
  }
  const std::vector<Eigen::Vector3d> claims = plans_.claims_except(robot);
  const MappingPipeline& mapping = mission_.mapping();
  if (!mission_.has_map() || mapping.scan_poses().empty()) {
    throw GoalRefused("no_map", "there is no map yet: take a first scan");
  }
  const PlannerConfig& planner = mission_.planner();
  const Pose at = scan_pose_of_.at(robot);
  const Eigen::Vector3d from(at.x, at.y, at.z);
  // The region this robot can reach, flooded from where it stands (the pipeline's is the last
  // scanning robot's, and two robots may stand in parts of the site apart from each other).
  const MovableRegion movable = robot == last_scan_.second
                                    ? *mapping.movable()
                                    : movable_region(mapping.map(), from, planner.movable);
  const GoalSite site = goal_site(mapping, planner, movable, from, x, y);
  const Eigen::Vector2d centre = mapping.map().center_of(site.cell);
  const std::vector<Eigen::Vector2d> points = mapping.scan_points();
  CandidateRecord record;
  PlanInput input{mapping.map(), *mapping.target(), points, from};
  input.claimed = &claims;
  input.anchored = mission_.anchored_map();
  evaluate(input, planner, {centre.x(), centre.y(), site.floor_z}, &record.candidate);
  record.candidate.travel_m = site.travel.distance(site.cell);
  record.candidate.path = site.travel.path_to(site.cell);
  record.id = plans_.new_candidate_id();
  record.rank = 0;
  record.custom = true;
  plans_.add_candidate(robot, record);
  return record;
}

MissionParams LiveMap::params() const {
  std::lock_guard lock(encode_mutex_);
  return {mission_.planner(), mission_.mapping().target()};
}

void LiveMap::set_params(const MissionParams& params) {
  std::lock_guard encode_lock(encode_mutex_);
  const MissionParams before{mission_.planner(), mission_.mapping().target()};
  const auto apply = [&](const MissionParams& p) {
    claim_separation_m_ = p.planner.claim_separation_m;
    mission_.set_planner(p.planner);
    if (p.target) mission_.set_target(*p.target);
    return refresh_derived({});
  };
  std::vector<PlanRecord> plans;
  try {
    plans = apply(params);
  } catch (...) {
    // All or nothing: a region the machine cannot segment (out of memory) leaves the mission
    // as it was, not half changed and failing every later scan.
    apply(before);
    throw;
  }
  if (on_plan) {
    for (const PlanRecord& plan : plans) on_plan(plan);
  }
}

LiveMap::Held LiveMap::held() const {
  std::lock_guard lock(mutex_);
  Held h;
  for (std::size_t i = 0; i < scans_.size(); ++i) {
    if (!in_map_[i]) continue;
    h.scans.push_back(scans_[i]);
    h.parts.push_back({static_cast<std::uint32_t>(scans_[i].id), placed_[i]});
  }
  return h;
}

std::vector<StoredScan> LiveMap::scans() const {
  std::lock_guard lock(mutex_);
  return scans_;
}

std::vector<std::int64_t> LiveMap::waiting() const {
  std::vector<std::int64_t> out;
  for (const auto& [id, why] : waiting_reasons()) out.push_back(id);
  return out;
}

std::map<std::int64_t, std::string> LiveMap::waiting_reasons() const {
  std::lock_guard lock(mutex_);
  std::map<std::int64_t, std::string> out;
  for (std::size_t i = 0; i < scans_.size(); ++i) {
    if (!in_map_[i]) out[scans_[i].id] = i < outside_.size() ? outside_[i] : "";
  }
  return out;
}

std::optional<StoredScan> LiveMap::last_scan() const {
  std::lock_guard lock(mutex_);
  if (scans_.empty()) return std::nullopt;
  return scans_.back();
}

std::size_t LiveMap::scan_count() const {
  std::lock_guard lock(mutex_);
  return scans_.size();
}

std::size_t LiveMap::point_count() const {
  std::lock_guard lock(mutex_);
  return point_count_;
}

Bounds3 LiveMap::bounds() const {
  std::lock_guard lock(mutex_);
  return bounds_;
}

namespace {

// A scan's map-frame points carried back into its own frame (the pipeline takes scans so).
PointCloud in_own_frame(const PointCloud& in_map, const Pose& placed) {
  const Eigen::Affine3f scan_from_map = placed.isometry().inverse().cast<float>();
  PointCloud own;
  own.reserve(in_map.size());
  for (std::size_t i = 0; i < in_map.size(); ++i) {
    own.push_back(scan_from_map * in_map.points[i], in_map.colors[i]);
  }
  return own;
}

}  // namespace

LiveMap::Rebuilt LiveMap::rebuild(const std::vector<StoredScan>& keep, const ScanLoader& load,
                                  const std::function<void(std::size_t)>& progress) {
  Rebuilt out;
  std::lock_guard encode_lock(encode_mutex_);
  // The points the map holds, with the pose they are at (read without mutex_: only writers,
  // holding encode_mutex_, change them).
  std::map<std::int64_t, std::pair<std::shared_ptr<const PointCloud>, Pose>> held;
  for (std::size_t i = 0; i < scans_.size(); ++i) {
    held[scans_[i].id] = {placed_[i], scans_[i].placed};
  }
  // A new pipeline fed the kept scans in their order, each where its match put it: the MLS
  // map, the anchored map, the pose graph and the sensors' frame as if the others had never
  // come. The map frame and the target region stay.
  MissionPipeline fresh(mission_.config());
  fresh.set_planner(mission_.planner());
  if (const auto& target = mission_.mapping().target()) fresh.set_target(*target);
  std::vector<StoredScan> scans;
  for (const StoredScan& s : keep) {
    PointCloud own;
    if (const auto it = held.find(s.id); it != held.end()) {
      own = in_own_frame(*it->second.first, it->second.second);
    } else {
      try {
        own = load(s);
      } catch (const std::exception& e) {
        out.skipped.push_back({s, e.what()});  // its file is gone or damaged: the rest go on
        continue;
      }
    }
    fresh.add(own, placement_of(s));
    scans.push_back(s);
    if (progress) progress(scans.size());
  }
  mission_ = std::move(fresh);
  // Everything as the new pipeline has it; a scan whose points stay where they were keeps its
  // chunk.
  Followed f;
  std::map<std::int64_t, std::shared_ptr<const std::string>> chunks;
  for (std::size_t i = 0; i < scans.size(); ++i) {
    StoredScan& s = scans[i];
    s.placed = mission_.cloud_poses()[i];
    f.placed.push_back(mission_.placed_scans()[i]);
    f.in_map.push_back(mission_.in_map(i) ? 1 : 0);
    f.outside.push_back(mission_.outside_reason(i));
    f.bounds.push_back(bounds_of(*f.placed.back()));
    const auto was = held.find(s.id);
    const auto chunk = chunks_.find(s.id);
    const bool same = was != held.end() && chunk != chunks_.end() &&
                      pose_change(was->second.second, s.placed).metres == 0 &&
                      was->second.second.yaw == s.placed.yaw;
    chunks[s.id] = same ? chunk->second : nullptr;
  }
  // A robot stands where it last scanned, as the graph now has that scan; where that scan was
  // taken out, where it was (the robot has not moved).
  std::map<std::string, std::int64_t> last_of;
  for (const StoredScan& s : scans_) last_of[s.robot] = s.id;
  for (const StoredScan& s : scans) {
    if (last_of.count(s.robot) && last_of[s.robot] == s.id) scan_pose_of_[s.robot] = s.placed;
  }
  f.scans = std::move(scans);
  rethin(f, /*whole=*/true);
  out.plans = refresh_derived(
      [&] {
        commit(std::move(f));
        chunks_ = std::move(chunks);
      },
      /*scan_joined=*/false);
  encode_wanted_.notify_one();
  if (on_map) on_map(thinned_.cloud());
  if (on_plan) {
    for (const PlanRecord& plan : out.plans) on_plan(plan);
  }
  return out;
}

LiveMap::EncodedMap LiveMap::encoded_map(std::chrono::milliseconds wait) const {
  std::unique_lock lock(mutex_);
  if (scans_.empty()) return {};
  ++encode_waiters_;
  encode_wanted_.notify_one();
  encoded_changed_.wait_for(lock, wait,
                            [&] { return stopping_ || encoded_generation_ == generation_; });
  --encode_waiters_;
  return {encoded_, encoded_last_scan_};
}

std::optional<std::size_t> LiveMap::index_of(std::int64_t id) const {
  const auto it = std::lower_bound(scans_.begin(), scans_.end(), id,
                                   [](const StoredScan& s, std::int64_t v) { return s.id < v; });
  if (it == scans_.end() || it->id != id) return std::nullopt;
  return static_cast<std::size_t>(it - scans_.begin());
}

std::shared_ptr<const std::string> LiveMap::encoded_chunk(std::int64_t id) const {
  std::shared_ptr<const PointCloud> points;
  {
    std::lock_guard lock(mutex_);
    const auto at = index_of(id);
    if (!at) return nullptr;
    if (const auto it = chunks_.find(id); it != chunks_.end() && it->second) return it->second;
    points = placed_[*at];
  }
  // A new scan, or one the graph moved: its chunk is made when first asked for, outside the
  // lock.
  if (points->empty()) return nullptr;
  auto chunk = std::make_shared<const std::string>(encode_draco(*points));
  std::lock_guard lock(mutex_);
  if (const auto at = index_of(id); at && placed_[*at] == points) chunks_[id] = chunk;
  return chunk;
}

LiveMap::EncodedMap LiveMap::encoded_since(std::int64_t since_id) const {
  PointCloud tail;
  std::int64_t last = 0;
  bool whole = false;
  std::optional<std::int64_t> one;
  {
    std::lock_guard lock(mutex_);
    if (scans_.empty()) return {};
    last = scans_.back().id;
    std::size_t first = scans_.size();
    for (std::size_t i = 0; i < scans_.size(); ++i) {
      if (scans_[i].id > since_id) {
        first = i;
        break;
      }
    }
    if (first == scans_.size()) return {nullptr, last};
    whole = first == 0;
    one = first + 1 == scans_.size() ? std::optional(scans_[first].id) : std::nullopt;
    if (one && !in_map_[first]) return {nullptr, last};
    if (!whole && !one) {
      for (std::size_t i = first; i < placed_.size(); ++i) {
        if (in_map_[i]) tail.append(*placed_[i]);
      }
    }
  }
  // The common case, one scan behind, is encoded already.
  if (one) return {encoded_chunk(*one), last};
  if (whole) return encoded_map();
  if (tail.empty()) return {nullptr, last};
  return {std::make_shared<const std::string>(encode_draco(tail)), last};
}

LiveMap::EncodedMap LiveMap::encoded_range(std::int64_t since_id, std::int64_t until_id) const {
  PointCloud part;
  std::int64_t last = 0;
  std::optional<std::int64_t> one;
  {
    std::lock_guard lock(mutex_);
    std::size_t first = scans_.size(), end = 0;
    for (std::size_t i = 0; i < scans_.size(); ++i) {
      if (scans_[i].id > until_id) break;
      last = scans_[i].id;
      if (scans_[i].id > since_id) {
        first = std::min(first, i);
        end = i + 1;
      }
    }
    if (first >= end) return {nullptr, last};
    if (first + 1 == end) {
      if (!in_map_[first]) return {nullptr, last};
      one = scans_[first].id;
    } else {
      for (std::size_t i = first; i < end; ++i) {
        if (in_map_[i]) part.append(*placed_[i]);
      }
    }
  }
  if (one) return {encoded_chunk(*one), last};
  if (part.empty()) return {nullptr, last};
  return {std::make_shared<const std::string>(encode_draco(part)), last};
}

std::optional<MapAreas> LiveMap::areas_after(std::int64_t id) const {
  std::lock_guard lock(mutex_);
  const auto it = areas_after_.find(id);
  if (it == areas_after_.end()) return std::nullopt;
  return it->second;
}

LayerImage LiveMap::layer(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = layers_.find(name);
  if (it == layers_.end() || !layer_geometry_) return {};
  return {it->second, *layer_geometry_,
          name == "elevation" ? elevation_range_ : std::optional<HeightRange>{}};
}

std::optional<LayerGeometry> LiveMap::layer_geometry() const {
  std::lock_guard lock(mutex_);
  return layer_geometry_;
}

std::shared_ptr<const std::vector<std::uint8_t>> LiveMap::layer_png(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = layers_.find(name);
  return it == layers_.end() ? nullptr : it->second;
}

MapAreas LiveMap::areas() const {
  std::lock_guard lock(mutex_);
  return areas_;
}

}  // namespace scanplan::server

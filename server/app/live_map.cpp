#include "app/live_map.hpp"

#include <algorithm>
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

// The server keeps its own copies of what the pipeline places (points per scan, Draco chunks,
// the stored poses); until those follow the pose graph's corrections, its scans stay where the
// map match put them, as before the graph.
MissionConfig without_graph(MissionConfig config) {
  config.graph.reset();
  return config;
}

}  // namespace

LiveMap::LiveMap(PlanBook& plans, MissionConfig config)
    : mission_(without_graph(std::move(config))),
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
    encode_wanted_.wait(lock, [&] { return stopping_ || encoded_generation_ != generation_; });
    if (stopping_) return;
    const auto parts = placed_;
    const std::int64_t last = scans_.empty() ? 0 : scans_.back().id;
    const std::uint64_t generation = generation_;
    const std::size_t count = point_count_;
    lock.unlock();
    std::shared_ptr<const std::string> encoded;
    try {
      PointCloud all;
      all.reserve(count);
      for (const auto& p : parts) all.append(*p);
      if (!all.empty()) encoded = std::make_shared<const std::string>(encode_draco(all));
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

std::optional<MapMatch> LiveMap::place(const PointCloud& scan, const Pose& reported) const {
  // Only the copy of the map's points near the scan under the lock: the match itself takes
  // hundreds of milliseconds, and parameter changes and goals must not wait for it.
  std::optional<MissionPipeline::MatchInput> in;
  {
    std::lock_guard encode_lock(encode_mutex_);
    in = mission_.match_input(reported);
  }
  if (!in) return std::nullopt;
  return match_to_map(in->map_points, scan, in->prior, in->config);
}

std::vector<PlanRecord> LiveMap::add(const StoredScan& scan, const PointCloud& cloud) {
  const Pose& pose = scan.placed;
  // The scan in the map frame and its own Draco chunk first: should either fail (out of
  // memory, a Draco error), nothing of the scan has reached the map yet.
  std::shared_ptr<const PointCloud> shared = MissionPipeline::to_map_frame(cloud, pose);
  const Bounds3 added = bounds_of(*shared);
  std::shared_ptr<const std::string> chunk;
  if (!shared->empty()) chunk = std::make_shared<const std::string>(encode_draco(*shared));
  // Writers take turns on encode_mutex_; readers only wait for the short commit below, and
  // they see the scan, its points, its chunk and the plan that includes it appear together.
  std::lock_guard encode_lock(encode_mutex_);
  mission_.add(cloud, {scan.estimated, pose, scan.match && scan.match->applied}, shared);
  thinned_.add(*shared);
  last_scan_ = {scan.id, scan.robot};
  scan_pose_of_[scan.robot] = pose;
  const auto plans = refresh_derived([&] {
    scans_.push_back(scan);
    ++generation_;
    chunks_[scan.id] = chunk;
    point_count_ += shared->size();
    placed_.push_back(std::move(shared));
    if (added.valid()) {
      bounds_.extend(added.min);
      bounds_.extend(added.max);
    }
  });
  encode_wanted_.notify_one();
  // Outside mutex_ so readers are not held up, inside encode_mutex_ so maps and plans go out in
  // the order they were made; the map first, as the plan is made from it.
  if (on_map) on_map(thinned_.cloud());
  if (on_plan) {
    for (const PlanRecord& plan : plans) on_plan(plan);
  }
  return plans;
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
    if (!driving.count(robot)) robots.push_back({robot, {at.x, at.y, at.z}});
  }
  const PlannerConfig& planner = mission_.planner();
  std::vector<PlanRecord> records;
  for (FleetPlan& decided : mission_.plan(robots, std::move(claims))) {
    const Plan& plan = decided.plan;
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
                                                 bool scan_joined) {
  if (!mission_.has_map()) {
    std::lock_guard lock(mutex_);
    if (commit) commit();
    return {};
  }
  std::vector<PlanRecord> records = make_plans();
  auto layers = render_layers();
  const RegionMap& regions = *mission_.mapping().regions();
  const MapAreas areas{regions.completed_m2(), regions.low_resolution_m2(), regions.unscanned_m2(),
                       mission_.mapping().movable()->area_m2()};
  {
    // The scan, its map and everything derived from it appear to readers together.
    std::lock_guard lock(mutex_);
    if (commit) commit();
    plans_.replace(records, last_scan_.second);
    layers_ = std::move(layers);
    layer_geometry_ = geometry_of(regions);
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
  TravelMap travel =
      travel_map(map, movable, from, planner.movable, planner.stay_in_target ? &target : nullptr);
  if (!travel.reachable(cell)) {
    throw GoalRefused("unreachable", std::string(where) +
                                         " is movable but no drive inside the target region "
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

std::vector<StoredScan> LiveMap::scans() const {
  std::lock_guard lock(mutex_);
  return scans_;
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
  std::map<std::int64_t,
           std::pair<std::shared_ptr<const PointCloud>, std::shared_ptr<const std::string>>>
      held;
  {
    std::lock_guard lock(mutex_);
    for (std::size_t i = 0; i < scans_.size(); ++i) {
      const auto chunk = chunks_.find(scans_[i].id);
      held[scans_[i].id] = {placed_[i], chunk == chunks_.end() ? nullptr : chunk->second};
    }
  }
  // A new pipeline fed the kept scans in their order, at their placed poses: the MLS map, the
  // anchored map and the sensors' frame as if the others had never come. The map frame and the
  // target region stay.
  MissionPipeline fresh(mission_.config());
  fresh.set_planner(mission_.planner());
  if (const auto& target = mission_.mapping().target()) fresh.set_target(*target);
  VoxelMap thinned{kThinnedMapVoxelM};
  std::vector<StoredScan> scans;
  std::vector<std::shared_ptr<const PointCloud>> placed;
  std::map<std::int64_t, std::shared_ptr<const std::string>> chunks;
  std::map<std::string, Pose> pose_of;
  Bounds3 bounds;
  std::size_t count = 0;
  for (const StoredScan& s : keep) {
    auto [in_map, chunk] = held.count(s.id) ? held[s.id] : decltype(held)::mapped_type{};
    if (!in_map) {
      try {
        in_map = MissionPipeline::to_map_frame(load(s), s.placed);
      } catch (const std::exception& e) {
        out.skipped.push_back({s, e.what()});  // its file is gone or damaged: the rest go on
        continue;
      }
    }
    if (!chunk && !in_map->empty()) {
      chunk = std::make_shared<const std::string>(encode_draco(*in_map));
    }
    fresh.add(in_own_frame(*in_map, s.placed), {s.estimated, s.placed, s.match && s.match->applied},
              in_map);
    thinned.add(*in_map);
    const Bounds3 b = bounds_of(*in_map);
    if (b.valid()) {
      bounds.extend(b.min);
      bounds.extend(b.max);
    }
    count += in_map->size();
    pose_of[s.robot] = s.placed;
    scans.push_back(s);
    placed.push_back(std::move(in_map));
    chunks[s.id] = std::move(chunk);
    if (progress) progress(scans.size());
  }
  mission_ = std::move(fresh);
  thinned_ = std::move(thinned);
  // Where each robot last scanned stays where it is: the robot has not moved.
  for (const auto& [robot, pose] : pose_of) scan_pose_of_.try_emplace(robot, pose);
  out.plans = refresh_derived(
      [&] {
        scans_ = std::move(scans);
        placed_ = std::move(placed);
        chunks_ = std::move(chunks);
        point_count_ = count;
        bounds_ = bounds;
        ++generation_;
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
  encoded_changed_.wait_for(lock, wait,
                            [&] { return stopping_ || encoded_generation_ == generation_; });
  return {encoded_, encoded_last_scan_};
}

std::shared_ptr<const std::string> LiveMap::encoded_chunk(std::int64_t id) const {
  std::lock_guard lock(mutex_);
  const auto it = chunks_.find(id);
  return it == chunks_.end() ? nullptr : it->second;
}

LiveMap::EncodedMap LiveMap::encoded_since(std::int64_t since_id) const {
  PointCloud tail;
  std::int64_t last = 0;
  bool whole = false;
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
    // The common case, one scan behind, is already encoded.
    if (first + 1 == scans_.size()) return {chunks_.at(scans_[first].id), last};
    if (!whole) {
      for (std::size_t i = first; i < placed_.size(); ++i) tail.append(*placed_[i]);
    }
  }
  if (whole) return encoded_map();
  if (tail.empty()) return {nullptr, last};
  return {std::make_shared<const std::string>(encode_draco(tail)), last};
}

LiveMap::EncodedMap LiveMap::encoded_range(std::int64_t since_id, std::int64_t until_id) const {
  PointCloud part;
  std::int64_t last = 0;
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
    if (first + 1 == end) return {chunks_.at(scans_[first].id), last};
    for (std::size_t i = first; i < end; ++i) part.append(*placed_[i]);
  }
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
  return {it->second, *layer_geometry_};
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

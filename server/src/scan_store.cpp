#include "scan_store.hpp"

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

double approach_yaw_deg(const Candidate& c) {
  const auto& path = c.path;
  if (path.size() < 2) return 0;
  const Eigen::Vector2d d = path.back() - path[path.size() - 2];
  return rad2deg(std::atan2(d.y(), d.x()));
}

ScanStore::ScanStore(MissionConfig config)
    : mission_(std::move(config)),
      claim_separation_m_(mission_.planner().claim_separation_m),
      encoder_([this] { encode_loop(); }) {}

ScanStore::~ScanStore() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  encode_wanted_.notify_all();
  encoder_.join();
}

void ScanStore::encode_loop() {
  std::unique_lock lock(mutex_);
  for (;;) {
    encode_wanted_.wait(lock, [&] {
      return stopping_ || (!scans_.empty() && encoded_last_scan_ != scans_.back().id);
    });
    if (stopping_) return;
    const auto parts = placed_;
    const std::int64_t last = scans_.back().id;
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
      encoded_changed_.notify_all();
      continue;
    }
    lock.lock();
    encoded_ = std::move(encoded);
    encoded_last_scan_ = last;
    encoded_changed_.notify_all();
  }
}

const std::vector<std::string>& ScanStore::layer_names() {
  static const std::vector<std::string> kNames = {"regions", "elevation", "movable"};
  return kNames;
}

std::optional<MapMatch> ScanStore::place(const PointCloud& scan, const Pose& reported) const {
  std::lock_guard encode_lock(encode_mutex_);
  return mission_.place(scan, reported);
}

void ScanStore::add(const StoredScan& scan, const PointCloud& cloud) {
  const Pose& pose = scan.placed;
  // Writers take turns on encode_mutex_; readers only wait for the short commit below, and
  // they see the scan, its points, its chunk and the plan that includes it appear together.
  std::lock_guard encode_lock(encode_mutex_);
  std::shared_ptr<const PointCloud> shared = mission_.add(cloud, pose);
  const Bounds3 added = bounds_of(*shared);
  std::shared_ptr<const std::string> chunk;
  if (!shared->empty()) chunk = std::make_shared<const std::string>(encode_draco(*shared));

  thinned_.add(*shared);
  last_scan_ = {scan.id, scan.robot};
  scan_pose_of_[scan.robot] = pose;
  const auto plans = refresh_derived([&] {
    scans_.push_back(scan);
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
}

namespace {

// The candidate the plan's robot is driving to (an approved move under way), if any.
const CandidateRecord* active_goal(const PlanRecord& plan) {
  for (const CandidateRecord& c : plan.candidates) {
    if (c.state == "moving") return &c;
  }
  return nullptr;
}

}  // namespace

std::vector<Eigen::Vector3d> ScanStore::claims_except(const std::string& robot) const {
  std::vector<Eigen::Vector3d> claims;
  for (const auto& [id, plan] : plans_) {
    if (id == robot) continue;
    const CandidateRecord* goal = active_goal(plan);
    for (const CandidateRecord& c : plan.candidates) {
      if (!goal && c.state == "proposed" && c.rank == 1) goal = &c;
    }
    if (goal) claims.push_back(goal->candidate.position);
  }
  return claims;
}

std::vector<PlanRecord> ScanStore::refresh_derived(const std::function<void()>& commit) {
  const MappingPipeline& mapping = mission_.mapping();
  if (!mission_.has_map()) {
    std::lock_guard lock(mutex_);
    if (commit) commit();
    return {};
  }
  const RegionMap& regions = *mapping.regions();
  const MovableRegion& movable = *mapping.movable();
  const std::vector<Eigen::Vector2d> points = mapping.scan_points();

  // Several robots share the map: they are decided one after another (plan_fleet), each
  // counting what the robots before it will scan as taken (PlanInput::claimed), so no two are
  // sent to one spot. A robot driving to an approved goal keeps its plan, and its goal is
  // claimed first.
  std::vector<Eigen::Vector3d> claims;
  std::set<std::string> driving;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [robot, plan] : plans_) {
      if (const CandidateRecord* goal = active_goal(plan)) {
        claims.push_back(goal->candidate.position);
        driving.insert(robot);
      }
    }
  }
  std::vector<FleetRobot> robots;
  for (const auto& [robot, at] : scan_pose_of_) {
    if (!driving.count(robot)) robots.push_back({robot, {at.x, at.y, at.z}});
  }
  std::vector<PlanRecord> records;
  const PlannerConfig& planner = mission_.planner();
  for (FleetPlan& decided : mission_.plan(robots, std::move(claims))) {
    const Plan& plan = decided.plan;
    PlanRecord record;
    record.id = next_plan_id_++;
    record.based_on_scan = last_scan_.first;
    record.robot = decided.robot;
    for (std::size_t k = 0; k < plan.ranked.size(); ++k) {
      CandidateRecord c;
      c.id = next_candidate_id_++;
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

  const auto png = [](const cv::Mat& img) {
    return std::make_shared<const std::vector<std::uint8_t>>(encode_png(img));
  };
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> layers;
  // The candidates are not drawn in: clients draw them over the layer (the page does, with
  // their states), and the layer stays the paper's Fig. 4/5.
  layers["regions"] = png(render_regions(regions, &movable, points));
  layers["elevation"] = png(render_elevation(mapping.map(), regions));
  layers["movable"] = png(render_movable(mapping.map(), movable, regions));
  const MapAreas areas{regions.completed_m2(), regions.low_resolution_m2(), regions.unscanned_m2(),
                       movable.area_m2()};
  // The layers' pixels in the map, as top_view_pixel places them.
  LayerGeometry geometry;
  {
    const auto& g = regions.cells;
    const int s = std::max(1, TopViewStyle{}.px_per_cell);
    geometry.min_x = g.origin.x * g.cell_m;
    geometry.min_y = g.origin.y * g.cell_m;
    geometry.max_x = (g.origin.x + g.cols) * g.cell_m;
    geometry.max_y = (g.origin.y + g.rows) * g.cell_m;
    geometry.px_per_m = s / g.cell_m;
    geometry.width = g.cols * s;
    geometry.height = g.rows * s;
  }

  {
    // The scan, its map and everything derived from it appear to readers together.
    std::lock_guard lock(mutex_);
    if (commit) commit();
    for (const PlanRecord& record : records) {
      if (const auto old = plans_.find(record.robot); old != plans_.end()) {
        for (auto& c : old->second.candidates) {
          if (c.state == "proposed") c.state = "superseded";
        }
      }
      plans_[record.robot] = record;
    }
    latest_robot_ = last_scan_.second;
    layers_ = std::move(layers);
    layer_geometry_ = geometry;
    areas_ = areas;
    // A commit means a scan joined (set_params re-segments without one).
    if (commit) areas_after_[last_scan_.first] = areas;
  }
  return records;
}

std::optional<PlanRecord> ScanStore::plan(const std::string& robot) const {
  std::lock_guard lock(mutex_);
  const auto it = plans_.find(robot.empty() ? latest_robot_ : robot);
  if (it == plans_.end()) return std::nullopt;
  return it->second;
}

std::vector<PlanRecord> ScanStore::plans() const {
  std::lock_guard lock(mutex_);
  std::vector<PlanRecord> out;
  for (const auto& [robot, plan] : plans_) out.push_back(plan);
  return out;
}

CandidateRecord* ScanStore::find_candidate(std::uint64_t id) {
  for (auto& [robot, plan] : plans_) {
    for (auto& c : plan.candidates) {
      if (c.id == id) return &c;
    }
  }
  return nullptr;
}

CandidateRecord ScanStore::add_goal(double x, double y, const std::string& robot_id) {
  std::lock_guard encode_lock(encode_mutex_);
  std::string robot;
  std::vector<Eigen::Vector3d> claims;
  {
    std::lock_guard lock(mutex_);
    if (plans_.empty()) throw GoalRefused("no_map", "there is no map yet: take a first scan");
    robot = robot_id.empty() ? latest_robot_ : robot_id;
    if (!plans_.count(robot)) {
      throw GoalRefused("unknown_robot",
                        "robot '" + robot + "' has no plan: it has not sent a scan yet");
    }
    claims = claims_except(robot);
  }
  const MappingPipeline& mapping = mission_.mapping();
  if (!mission_.has_map() || mapping.scan_poses().empty()) {
    throw GoalRefused("no_map", "there is no map yet: take a first scan");
  }
  const PlannerConfig& planner = mission_.planner();
  const MlsMap& map = mapping.map();
  const TargetRegion& target = *mapping.target();
  const Pose at = scan_pose_of_.at(robot);
  const Eigen::Vector3d from(at.x, at.y, at.z);
  // The region this robot can reach, flooded from where it stands (the pipeline's is the last
  // scanning robot's, and two robots may stand in parts of the site apart from each other).
  const MovableRegion movable =
      robot == last_scan_.second ? *mapping.movable() : movable_region(map, from, planner.movable);
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
  const TravelMap travel =
      travel_map(map, movable, from, planner.movable, planner.stay_in_target ? &target : nullptr);
  if (!travel.reachable(cell)) {
    throw GoalRefused("unreachable", std::string(where) +
                                         " is movable but no drive inside the target region "
                                         "leads there from the robot");
  }
  const auto offset = movable.patch.offset(cell);
  const float floor_z = map.cell(cell)->patches[movable.patch.values[*offset]].mean_z;
  const Eigen::Vector2d centre = map.center_of(cell);
  const std::vector<Eigen::Vector2d> points = mapping.scan_points();
  CandidateRecord record;
  PlanInput input{map, target, points, from};
  input.claimed = &claims;
  evaluate(input, planner, {centre.x(), centre.y(), floor_z}, &record.candidate);
  record.candidate.travel_m = travel.distance(cell);
  record.candidate.path = travel.path_to(cell);
  record.id = next_candidate_id_++;
  record.rank = 0;
  record.custom = true;
  std::lock_guard lock(mutex_);
  plans_.at(robot).candidates.push_back(record);
  return record;
}

bool ScanStore::set_candidate_state(std::uint64_t id, const std::string& state,
                                    const std::string& note) {
  std::lock_guard lock(mutex_);
  CandidateRecord* c = find_candidate(id);
  if (!c) return false;
  c->state = state;
  c->note = note;
  return true;
}

MissionParams ScanStore::params() const {
  std::lock_guard lock(encode_mutex_);
  return {mission_.planner(), mission_.mapping().target()};
}

void ScanStore::set_params(const MissionParams& params) {
  std::lock_guard encode_lock(encode_mutex_);
  claim_separation_m_ = params.planner.claim_separation_m;
  mission_.set_planner(params.planner);
  if (params.target) mission_.set_target(*params.target);
  const auto plans = refresh_derived({});
  if (on_plan) {
    for (const PlanRecord& plan : plans) on_plan(plan);
  }
}

std::vector<StoredScan> ScanStore::scans() const {
  std::lock_guard lock(mutex_);
  return scans_;
}

std::optional<StoredScan> ScanStore::last_scan() const {
  std::lock_guard lock(mutex_);
  if (scans_.empty()) return std::nullopt;
  return scans_.back();
}

std::size_t ScanStore::scan_count() const {
  std::lock_guard lock(mutex_);
  return scans_.size();
}

std::size_t ScanStore::point_count() const {
  std::lock_guard lock(mutex_);
  return point_count_;
}

Bounds3 ScanStore::bounds() const {
  std::lock_guard lock(mutex_);
  return bounds_;
}

ScanStore::EncodedMap ScanStore::encoded_map(std::chrono::milliseconds wait) const {
  std::unique_lock lock(mutex_);
  if (scans_.empty()) return {};
  encoded_changed_.wait_for(lock, wait,
                            [&] { return stopping_ || encoded_last_scan_ == scans_.back().id; });
  return {encoded_, encoded_last_scan_};
}

std::shared_ptr<const std::string> ScanStore::encoded_chunk(std::int64_t id) const {
  std::lock_guard lock(mutex_);
  const auto it = chunks_.find(id);
  return it == chunks_.end() ? nullptr : it->second;
}

ScanStore::EncodedMap ScanStore::encoded_since(std::int64_t since_id) const {
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

ScanStore::EncodedMap ScanStore::encoded_range(std::int64_t since_id, std::int64_t until_id) const {
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

std::optional<MapAreas> ScanStore::areas_after(std::int64_t id) const {
  std::lock_guard lock(mutex_);
  const auto it = areas_after_.find(id);
  if (it == areas_after_.end()) return std::nullopt;
  return it->second;
}

LayerImage ScanStore::layer(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = layers_.find(name);
  if (it == layers_.end() || !layer_geometry_) return {};
  return {it->second, *layer_geometry_};
}

std::optional<LayerGeometry> ScanStore::layer_geometry() const {
  std::lock_guard lock(mutex_);
  return layer_geometry_;
}

std::shared_ptr<const std::vector<std::uint8_t>> ScanStore::layer_png(
    const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = layers_.find(name);
  return it == layers_.end() ? nullptr : it->second;
}

MapAreas ScanStore::areas() const {
  std::lock_guard lock(mutex_);
  return areas_;
}

void ScanStore::set_scan_state(const std::string& robot_id, RobotScanState state) {
  std::lock_guard lock(mutex_);
  robots_[robot_id].scan = std::move(state);
}

void ScanStore::set_robot_status(const std::string& robot_id, RobotStatus status) {
  std::lock_guard lock(mutex_);
  robots_[robot_id].status = std::move(status);
}

void ScanStore::set_robot_connection(const std::string& robot_id, RobotConnection connection) {
  std::lock_guard lock(mutex_);
  robots_[robot_id].connection = std::move(connection);
}

std::map<std::string, RobotState> ScanStore::robot_states() const {
  std::lock_guard lock(mutex_);
  return robots_;
}

}  // namespace scanplan::server

#include "app/scan_intake.hpp"

#include "app/domain_json.hpp"
#include "common/iso_time.hpp"
#include "common/text_fields.hpp"
#include "scanplan/geometry/pose_limits.hpp"
#include "scanplan/geometry/scan_returns.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>

namespace scanplan::server {

ScanIntake::ScanIntake(SessionStore& session, LiveMap& live, const Events& events)
    : session_(session), live_(live), events_(events) {}

ScanIntake::~ScanIntake() {
  stop();
}

void ScanIntake::start() {
  {
    std::lock_guard lock(mutex_);
    stop_ = false;
  }
  // Taken before anything can submit, so no scan is both on this list and in the queue.
  std::vector<StoredScan> existing = session_.scans();
  {
    std::lock_guard lock(mutex_);
    if (!existing.empty()) rebuild_ = Rebuild{0, existing.size()};
  }
  worker_ = std::thread([this, existing = std::move(existing)] {
    // A restarted server rebuilds its map from the session on disk, scan by scan, while it
    // already answers requests (and says so: rebuilding()).
    for (const StoredScan& s : existing) {
      {
        std::lock_guard lock(mutex_);
        if (stop_) return;
      }
      if (s.excluded) {
        std::lock_guard lock(mutex_);
        ++rebuild_->done;
        continue;
      }
      std::string problem;
      if (const auto why = implausible_pose(s.placed)) {
        problem = "its stored pose is not a place: " + *why;
      } else {
        try {
          process(s, load(s), /*restoring=*/true);
        } catch (const std::exception& e) {
          problem = e.what();
        }
      }
      std::lock_guard lock(mutex_);
      if (!problem.empty()) {
        spdlog::error("scan {} of the session cannot be brought back: {}", s.id, problem);
        not_in_map_.push_back({s.id, s.robot, problem});
      }
      ++rebuild_->done;
    }
    if (!existing.empty()) {
      try {
        resume_poses();
      } catch (const std::exception& e) {
        spdlog::error("the session's latest poses could not be read: {}", e.what());
      }
    }
    {
      std::lock_guard lock(mutex_);
      rebuild_.reset();
    }
    loop();
  });
}

void ScanIntake::stop() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

SubmittedScan ScanIntake::submit(const std::string& robot, const Pose& estimated,
                                 std::int64_t stamp_ns, PointCloud cloud) {
  const auto refuse = [&](auto error) {
    spdlog::warn("scan from '{}' refused: {}", robot, error.what());
    events_.publish("scan_rejected", {{"robot", robot}, {"reason", error.what()}});
    throw error;
  };
  if (const auto why = robot_id_problem(robot)) refuse(InvalidScanError(*why));
  if (const auto why = implausible_pose(estimated)) refuse(InvalidScanError(*why));
  // The laser sits sensor_height_m above the origin of the robot frame our scans use; data
  // recorded about the laser itself (a 3DTK replay) shows it by a saturation shell there.
  ReturnFilterConfig returns;
  const Eigen::Vector3f robot_frame(0, 0, static_cast<float>(live_.sensor_height_m()));
  returns.sensor = locate_sensor(cloud, {robot_frame, Eigen::Vector3f::Zero()}, returns);
  const DroppedReturns dropped = drop_bad_returns(cloud, returns);
  if (cloud.size() < kMinScanPoints) {
    refuse(UnusableScanError(std::to_string(cloud.size()) +
                             " of the scan's points are measurements, at least " +
                             std::to_string(kMinScanPoints) +
                             " are needed (dropped: " + std::to_string(dropped.non_finite) +
                             " not finite, " + std::to_string(dropped.out_of_range) + " beyond " +
                             std::to_string(static_cast<int>(returns.max_range_m)) + " m, " +
                             std::to_string(dropped.mount) + " on the scanner's mount, " +
                             std::to_string(dropped.saturated) + " in a saturation shell)"));
  }
  if (dropped.total() > 0) {
    spdlog::info(
        "scan from '{}': dropped {} not finite, {} out of range, {} on the mount, {} saturated",
        robot, dropped.non_finite, dropped.out_of_range, dropped.mount, dropped.saturated);
  }
  // Matching will correct `placed`; until then the reported pose is the best there is.
  const std::optional<ReachedGoal> goal = live_.take_reached_goal(robot);
  StoredScan stored = session_.add_scan(robot, estimated, estimated, stamp_ns, cloud,
                                        goal ? std::optional(goal->position) : std::nullopt,
                                        goal ? goal->drive_m : 0);
  {
    std::lock_guard lock(mutex_);
    queue_.push_back({stored, std::move(cloud)});
  }
  wake_.notify_one();
  events_.publish("scan_received", {{"scan", stored.id},
                                    {"robot", robot},
                                    {"points", stored.points},
                                    {"dropped", dropped_json(dropped)}});
  return {stored, dropped};
}

StoredScan ScanIntake::match(StoredScan scan, const PointCloud& cloud) {
  const std::optional<MapMatch> matched =
      live_.place(cloud, scan.estimated, scan.robot, scan.goal_drive_m);
  if (!matched) return scan;
  const MapMatch& m = *matched;
  const Pose& e = scan.estimated;
  const Pose& p = m.placed;
  scan.match = StoredMatch{m.applied,        m.result.converged,
                           m.result.method,  m.applied ? std::string() : m.result.message,
                           m.result.time_ms, m.result.inlier_ratio,
                           m.information,    m.result.weakest_constraint};
  // Refused, the match leaves the scan at its reported pose carried into the map frame.
  scan.placed = p;
  try {
    session_.record_match(scan.id, *scan.match, p);
  } catch (const SessionStoreError& failure) {
    // The scan was acknowledged: it joins the map whatever the disk says; a restart would
    // bring it back at its reported pose.
    const std::string message = "the match of scan " + std::to_string(scan.id) +
                                " could not be recorded in the session: " + failure.what();
    spdlog::error("{}", message);
    {
      std::lock_guard lock(mutex_);
      storage_failure_ = StorageFailure{iso8601_utc_now(), message};
    }
    events_.publish("storage_failed", {{"scan", scan.id}, {"message", message}});
  }
  events_.publish("match_done", match_done_json(scan.id, e, m));
  if (!m.applied) {
    spdlog::warn("scan {} stays at its reported pose (in the map frame): {}", scan.id,
                 m.result.message);
    return scan;
  }
  spdlog::info("scan {} matched ({}): moved {:.2f} m, {:.2f}°, score {:.1f}, {:.0f} ms", scan.id,
               m.result.method, std::hypot(p.x - e.x, p.y - e.y),
               rad2deg(std::remainder(p.yaw - e.yaw, 2 * M_PI)), m.result.score, m.result.time_ms);
  return scan;
}

void ScanIntake::process(const StoredScan& scan, const PointCloud& cloud, bool restoring,
                         std::optional<double> match_ms) {
  LiveMap::Added added = live_.add(scan, cloud);
  // What the operator waits for goes out first: the new candidates (a few kilobytes), then the
  // scan's chunk for the 3-D view (a megabyte on the link, perhaps encoded now).
  publish_plans(std::move(added.plans), scan.robot);
  // A scan waiting outside the map is not shown: it may be metres off.
  if (added.in_map) {
    if (const auto chunk = live_.encoded_chunk(scan.id)) events_.map_chunk(scan.id, *chunk);
  }
  // Brought back after a restart, the graph retraces the corrections already recorded: the
  // session gets one revision once all scans are back (resume_poses).
  if (!restoring) record_correction(added.corrected);
  // The scan's last word: a client that saw it has every event of the scan.
  const MapAreas a = live_.areas();
  const LiveMap::AddTimes& t = added.times;
  nlohmann::json stages = {
      {"graph", t.graph}, {"map", t.map}, {"thin", t.thin}, {"plan", t.plan}, {"layers", t.layers}};
  if (match_ms) stages["match"] = *match_ms;
  events_.publish("map_updated",
                  map_updated_json(scan, a, added.in_map, added.outside, std::move(stages)));
}

void ScanIntake::publish_plans(std::vector<PlanRecord> plans, const std::string& first) {
  // One plan per robot that is not driving, by robot id; the scanning robot's first.
  std::sort(plans.begin(), plans.end(),
            [](const PlanRecord& p, const PlanRecord& q) { return p.robot < q.robot; });
  std::stable_partition(plans.begin(), plans.end(),
                        [&](const PlanRecord& p) { return p.robot == first; });
  for (const PlanRecord& plan : plans) {
    events_.publish("plan_done", plan_done_json(plan));
  }
}

void ScanIntake::record_correction(const MapCorrected& corrected) {
  std::int64_t revision = 0;
  if (!corrected.poses.empty()) {
    try {
      revision = session_.record_pose_revision(corrected.poses);
    } catch (const SessionStoreError& failure) {
      // The map moved all the same; a restart retraces the graph from the recorded matches.
      const std::string message =
          std::string("the corrected poses could not be recorded in the session: ") +
          failure.what();
      spdlog::error("{}", message);
      {
        std::lock_guard lock(mutex_);
        storage_failure_ = StorageFailure{iso8601_utc_now(), message};
      }
      events_.publish("storage_failed", {{"message", message}});
    }
  }
  if (corrected.empty()) return;
  spdlog::info(
      "map corrected (revision {}): {} scans moved up to {:.3f} m / {:.2f}°, {} joined, {} left",
      revision, corrected.moved.size(), corrected.max_moved_m, corrected.max_turned_deg,
      corrected.joined.size(), corrected.left.size());
  // In the mission's record too: the operator's log shows it after a reload or reconnection.
  publish_recorded(events_, session_, "map_corrected", map_corrected_json(corrected, revision));
}

void ScanIntake::resume_poses() {
  // The graph rebuilt from the recorded matches should stand where the session's latest
  // revision left it; where it does not (a revision lost to a full disk, a solver that settled
  // differently, a scan taken out of the map or put back), what the map now shows is recorded
  // as a revision of its own.
  std::map<std::int64_t, RevisedPose> recorded;
  for (const RevisedPose& r : session_.latest_poses()) recorded[r.scan] = r;
  const std::vector<std::int64_t> waiting = live_.waiting();
  MapCorrected differ;
  for (const StoredScan& s : live_.scans()) {
    const bool in_map = !std::binary_search(waiting.begin(), waiting.end(), s.id);
    const auto it = recorded.find(s.id);
    const Pose was = it == recorded.end() ? session_.scan(s.id)->placed : it->second.pose;
    const bool was_in = it == recorded.end() || it->second.in_map;
    const PoseChange moved = pose_change(was, s.placed);
    if (moved.metres <= kResumeToleranceM && in_map == was_in) continue;
    differ.poses.push_back({s.id, s.placed, in_map});
    if (in_map && !was_in) {
      differ.joined.push_back(s.id);
    } else if (!in_map && was_in) {
      differ.left.push_back(s.id);
    } else if (in_map) {
      differ.moved.push_back(s.id);
      differ.max_moved_m = std::max(differ.max_moved_m, moved.metres);
      differ.max_turned_deg = std::max(differ.max_turned_deg, moved.degrees);
    }
  }
  if (differ.poses.empty()) return;
  spdlog::warn("{} scans are not where the session's latest poses had them: a new revision",
               differ.poses.size());
  // As any correction: recorded, and told to the pages, which fetch those scans again.
  record_correction(differ);
}

std::size_t ScanIntake::pending() const {
  std::lock_guard lock(mutex_);
  return static_cast<std::size_t>(
      std::count_if(queue_.begin(), queue_.end(), [](const Job& j) { return j.scan.has_value(); }));
}

StoredScan ScanIntake::set_excluded(std::int64_t id, bool excluded, const std::string& by,
                                    const std::string& reason) {
  std::lock_guard lock(exclusion_mutex_);
  const std::optional<StoredScan> now = session_.scan(id);
  if (!now) throw ExclusionError("not_found", "no scan " + std::to_string(id) + " in this session");
  if (excluded && now->excluded) {
    throw ExclusionError("already_excluded", "scan " + std::to_string(id) +
                                                 " is already out of the map (taken out by " +
                                                 now->excluded->by + ")");
  }
  if (!excluded && !now->excluded) {
    throw ExclusionError("not_excluded", "scan " + std::to_string(id) + " is in the map");
  }
  if (excluded) {
    const std::vector<StoredScan> all = session_.scans();
    const auto in_map =
        std::count_if(all.begin(), all.end(), [](const StoredScan& s) { return !s.excluded; });
    if (in_map <= 1) {
      throw ExclusionError("last_scan",
                           "scan " + std::to_string(id) +
                               " is the only one in the map: taking it out would leave nothing "
                               "to plan on");
    }
  }
  const std::optional<StoredScan> after = session_.set_excluded(id, excluded, by, reason);
  if (!after)
    throw ExclusionError("not_found", "no scan " + std::to_string(id) + " in this session");
  events_.publish(excluded ? "scan_excluded" : "scan_restored",
                  {{"scan", id}, {"by", by}, {"reason", reason}});
  {
    std::lock_guard queue_lock(mutex_);
    queue_.push_back({});
  }
  wake_.notify_one();
  return *after;
}

PointCloud ScanIntake::load(const StoredScan& scan) const {
  PointCloud cloud = session_.load_points(scan);
  // A session written before points were checked on the way in may hold a point at 1e30 that
  // would spread the map over the world again at every restart: the unmeasurable ones go here
  // too (the mount and a saturation shell were dropped before the scan was stored).
  ReturnFilterConfig unmeasurable;
  unmeasurable.mount_radius_m = 0;
  unmeasurable.min_saturated_points = std::numeric_limits<std::size_t>::max();
  unmeasurable.sensor = Eigen::Vector3f(0, 0, static_cast<float>(live_.sensor_height_m()));
  drop_bad_returns(cloud, unmeasurable);
  return cloud;
}

std::vector<StoredScan> ScanIntake::excluded_scans() const {
  std::vector<StoredScan> out = session_.scans();
  std::erase_if(out, [](const StoredScan& s) { return !s.excluded; });
  return out;
}

void ScanIntake::rebuild_map() {
  std::vector<StoredScan> keep;
  for (StoredScan& s : session_.scans()) {
    if (s.excluded) continue;
    // A scan still queued joins with its own job; one that never came back stays out.
    {
      std::lock_guard lock(mutex_);
      const bool queued = std::any_of(queue_.begin(), queue_.end(),
                                      [&](const Job& j) { return j.scan && j.scan->id == s.id; });
      const bool missing = std::any_of(not_in_map_.begin(), not_in_map_.end(),
                                       [&](const NotInMap& n) { return n.id == s.id; });
      if (queued || missing) continue;
    }
    keep.push_back(std::move(s));
  }
  {
    std::lock_guard lock(mutex_);
    rebuild_ = Rebuild{0, keep.size()};
  }
  std::vector<PlanRecord> plans;
  try {
    LiveMap::Rebuilt rebuilt = live_.rebuild(
        keep, [this](const StoredScan& s) { return load(s); },
        [this](std::size_t done) {
          std::lock_guard lock(mutex_);
          if (rebuild_) rebuild_->done = done;
        });
    plans = std::move(rebuilt.plans);
    std::lock_guard lock(mutex_);
    for (const auto& [scan, why] : rebuilt.skipped) {
      spdlog::error("scan {} cannot be brought back into the map: {}", scan.id, why);
      not_in_map_.push_back({scan.id, scan.robot, why});
    }
  } catch (const std::exception& e) {
    spdlog::error("the map could not be rebuilt: {}", e.what());
  }
  // Without the scan taken out (or with the one put back) the graph may place the others
  // differently: recorded as a revision where it does.
  try {
    resume_poses();
  } catch (const std::exception& e) {
    spdlog::error("the rebuilt map's poses could not be recorded: {}", e.what());
  }
  {
    std::lock_guard lock(mutex_);
    rebuild_.reset();
  }
  const MapAreas a = live_.areas();
  events_.publish("map_rebuilt", {{"scans", keep.size()},
                                  {"completed_m2", a.completed_m2},
                                  {"low_resolution_m2", a.low_resolution_m2},
                                  {"unscanned_m2", a.unscanned_m2},
                                  {"movable_m2", a.movable_m2}});
  publish_plans(std::move(plans), {});
}

std::vector<ScanIntake::NotInMap> ScanIntake::not_in_map() const {
  std::lock_guard lock(mutex_);
  return not_in_map_;
}

std::optional<ScanIntake::Rebuild> ScanIntake::rebuilding() const {
  std::lock_guard lock(mutex_);
  return rebuild_;
}

std::optional<ScanIntake::StorageFailure> ScanIntake::last_storage_failure() const {
  std::lock_guard lock(mutex_);
  return storage_failure_;
}

void ScanIntake::loop() {
  for (;;) {
    Job job;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      job = std::move(queue_.front());
    }
    if (!job.scan) {
      rebuild_map();
    } else {
      StoredScan& scan = *job.scan;
      try {
        const auto started = std::chrono::steady_clock::now();
        scan = match(scan, job.cloud);
        const auto matched = std::chrono::steady_clock::now();
        process(scan, job.cloud, /*restoring=*/false,
                std::chrono::duration<double, std::milli>(matched - started).count());
        spdlog::info(
            "scan {} from '{}' is in the map: {} points at ({:.2f}, {:.2f}, {:.2f}), {:.0f} ms "
            "after matching",
            scan.id, scan.robot, scan.points, scan.placed.x, scan.placed.y, scan.placed.z,
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - matched)
                .count());
      } catch (const std::exception& e) {
        spdlog::error("scan {} could not join the map: {}", scan.id, e.what());
        std::lock_guard lock(mutex_);
        not_in_map_.push_back({scan.id, scan.robot, e.what()});
      }
    }
    std::lock_guard lock(mutex_);
    queue_.pop_front();
  }
}

}  // namespace scanplan::server

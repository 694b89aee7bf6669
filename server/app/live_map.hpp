#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "app/plan_book.hpp"
#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/io/map_export.hpp"
#include "scanplan/mapping/height_range.hpp"
#include "scanplan/mission/mission_pipeline.hpp"
#include "scanplan/planning/scan_planner.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// Areas of the target region's C / M / U segmentation and of the movable region (m²).
struct MapAreas {
  double completed_m2 = 0, low_resolution_m2 = 0, unscanned_m2 = 0, movable_m2 = 0;
};

// Where the top-view layers lie in the map: the image spans min.x..max.x left to right and
// max.y..min.y top to bottom (north up), px_per_m pixels a metre.
struct LayerGeometry {
  double min_x = 0, min_y = 0, max_x = 0, max_y = 0;
  double px_per_m = 0;
  int width = 0, height = 0;
};

struct LayerImage {
  std::shared_ptr<const std::vector<std::uint8_t>> png;  // null before the first scan
  LayerGeometry geometry;
  // The elevation layer's colour scale: the heights (m) of its first and last colour.
  std::optional<HeightRange> height_range;
};

// A goal the operator asked for that the robot cannot be sent to; `code` names the reason
// (no_map, outside_target, no_go, no_data, not_movable, unreachable).
class GoalRefused : public std::runtime_error {
 public:
  GoalRefused(std::string code_, const std::string& message)
      : std::runtime_error(message), code(std::move(code_)) {}
  std::string code;
};

// What the operator can change while the mission runs (PUT /api/v1/params).
struct MissionParams {
  PlannerConfig planner;
  std::optional<TargetRegion> target;  // nothing: the pipeline's default square
};

// What the pose graph did to the map when a scan joined (issue 17): scans it moved farther than
// MissionConfig::replace_m / _deg (their points re-placed, their chunks made anew), scans a match
// tied into the map at last, and scans that left it (the graph set their tie aside).
struct MapCorrected {
  std::vector<std::int64_t> moved, joined, left;  // scan ids, ascending
  double max_moved_m = 0, max_turned_deg = 0;     // of the moved scans
  // The poses to record as the session's next revision: every scan above, and the new scan
  // when the graph did not leave it where its match put it or it waits outside the map.
  std::vector<RevisedPose> poses;
  bool empty() const { return moved.empty() && joined.empty() && left.empty(); }
};

// The scans of this session, in the map frame, with what is derived from them: each scan's
// Draco chunk, the MLS map with its regions (the mission pipeline), the top-view layers as PNG
// and each robot's plan (into the plan book), rebuilt off the network thread each time a scan
// lands and published together. The whole map's Draco
// encoding grows with the session (seconds for millions of points), so it is made on a thread
// of its own after the scan is published: new candidates never wait for it.
class LiveMap {
 public:
  explicit LiveMap(PlanBook& plans, MissionConfig config = {});

  // Where the laser sits above a scan's origin (PipelineConfig::sensor_height_m).
  double sensor_height_m() const { return sensor_height_m_; }
  // Where `robot` was sent for the scan it sends now, if it arrived at an approved candidate
  // (PlanBook::take_reached_goal): stored with the scan.
  std::optional<ReachedGoal> take_reached_goal(const std::string& robot) {
    return plans_.take_reached_goal(robot);
  }
  ~LiveMap();
  LiveMap(const LiveMap&) = delete;
  LiveMap& operator=(const LiveMap&) = delete;

  // Side of the cubes the map is thinned to for subscribers who take the whole map at once
  // (DDS rt/scanplan/map): 0.3 m keeps walls, doorways and cars recognisable, and the yard
  // after a scan, or a campus block, stays within a few MB a message.
  static constexpr double kThinnedMapVoxelM = 0.3;

  // Told of each new thinned map (map frame, coloured, kThinnedMapVoxelM) and each new plan
  // (one per robot not driving to a goal; that of the robot whose scan came last told last),
  // on the thread that made them (the intake worker, or the one changing parameters). Set them
  // before the first add(). They run while the store's writers wait, so they must be quick and must
  // not call add() or the params functions.
  std::function<void(const PointCloud& thinned_map)> on_map;
  std::function<void(const PlanRecord& plan)> on_plan;

  // A stored scan joins the map: `cloud` is in the scan's own frame, `scan.placed` puts it in
  // the map frame (where its match put it; scan.match's information weighs it in the pose
  // graph). Scans must come in id order. Returns the plans made after it (one per robot not
  // driving to a goal; the scanning robot's last) and what the pose graph changed.
  // With the graph, a scan no believed match ties in waits outside the map (waiting()): its
  // points are in no map encoding, thinned map or bounds until it joins.
  // Where adding a scan went, wall clock in ms: the pose graph (pairs, refused scans matched
  // again, the solve), the map following it (MLS map, segmentation, movable region), the
  // thinned map, the plans, the layers' images.
  struct AddTimes {
    double graph = 0, map = 0, thin = 0, plan = 0, layers = 0;
  };
  struct Added {
    std::vector<PlanRecord> plans;
    MapCorrected corrected;
    bool in_map = true;   // the new scan joined the map (with the graph, it may wait outside)
    std::string outside;  // why it waits outside (MissionPipeline::outside_reason), else empty
    AddTimes times;
  };
  Added add(const StoredScan& scan, const PointCloud& cloud);

  // The map made anew from `keep` (stored scans, in id order, at their placed poses): after the
  // operator took a scan out or put one back. Points of scans the map holds are reused; the
  // others come from `load` (the scan in its own frame). `progress` is told how many are in.
  // A scan `load` cannot give (its file gone or damaged) is left out and named in `skipped`.
  using ScanLoader = std::function<PointCloud(const StoredScan&)>;
  struct Rebuilt {
    std::vector<PlanRecord> plans;                            // as add() returns them
    std::vector<std::pair<StoredScan, std::string>> skipped;  // with why
  };
  Rebuilt rebuild(const std::vector<StoredScan>& keep, const ScanLoader& load,
                  const std::function<void(std::size_t)>& progress = {});

  // The scans, in id order, each `placed` where the map has it now (the pose graph's latest).
  std::vector<StoredScan> scans() const;
  // The scans waiting outside the map for a match that ties them in, ascending.
  std::vector<std::int64_t> waiting() const;
  // Why each of them waits (MissionPipeline::outside_reason), by id.
  std::map<std::int64_t, std::string> waiting_reasons() const;
  // What the map holds (the scans not waiting outside it), each scan's points in the map frame
  // as drawn, with its stored record: what the exports write.
  struct Held {
    std::vector<StoredScan> scans;
    std::vector<MapPart> parts;
  };
  Held held() const;
  // Where a new scan of `robot` goes: matched against the map so far (MissionPipeline::place;
  // with drifting odometry from the robot's latest placed scan, `driven_m` the path it was sent
  // along since). Nothing when matching is off or the map is empty. Call from the thread that
  // calls add().
  std::optional<MapMatch> place(const PointCloud& scan, const Pose& reported,
                                const std::string& robot = {}, double driven_m = 0) const;
  std::size_t scan_count() const;
  std::optional<StoredScan> last_scan() const;
  std::size_t point_count() const;
  Bounds3 bounds() const;
  struct EncodedMap {
    std::shared_ptr<const std::string> draco;  // null when there are no points
    std::int64_t last_scan = 0;                // the newest scan included
  };
  // The whole map's encoding. When the encoder is still behind the newest scan, waits for it
  // up to `wait`; after that, the newest encoding there is (`last_scan` says which).
  EncodedMap encoded_map(std::chrono::milliseconds wait = std::chrono::seconds(15)) const;
  // The points of the scans after `since_id` only: what a browser that already holds the map
  // up to that scan needs.
  EncodedMap encoded_since(std::int64_t since_id) const;
  // The points of the scans with since_id < id <= until_id; last_scan is the newest scan
  // included, or when there is none the newest scan up to until_id in the map.
  EncodedMap encoded_range(std::int64_t since_id, std::int64_t until_id) const;
  // Scan `id`'s own points in the map frame, Draco-encoded (made when first asked for after the
  // scan moved); null for an unknown id or a scan without points.
  std::shared_ptr<const std::string> encoded_chunk(std::int64_t id) const;
  // A top-view layer as PNG: "regions", "elevation" or "movable"; null before the first scan.
  std::shared_ptr<const std::vector<std::uint8_t>> layer_png(const std::string& name) const;
  // The same with where it lies in the map (both from the same update).
  LayerImage layer(const std::string& name) const;
  std::optional<LayerGeometry> layer_geometry() const;
  static const std::vector<std::string>& layer_names();
  MapAreas areas() const;
  // The areas right after scan `id` joined the map (nothing for an unknown id).
  std::optional<MapAreas> areas_after(std::int64_t id) const;

  // Adds the operator's own goal at (x, y) to `robot`'s plan (empty: the robot whose scan came
  // last) as a custom candidate (rank 0), with F (Eq. 1, the other robots' goals claimed) and
  // the drive there over the movable region from the robot's last scan point.
  // Throws GoalRefused when there is no plan yet or the robot cannot stand or get there.
  CandidateRecord add_goal(double x, double y, const std::string& robot = "");
  MissionParams params() const;
  // How far apart two robots' goals must be (PlannerConfig::claim_separation_m), without
  // waiting for a plan being made.
  double claim_separation_m() const { return claim_separation_m_.load(); }
  // Applies new parameters and recomputes regions, layers and the plan.
  void set_params(const MissionParams& params);

 private:
  mutable std::mutex mutex_;
  std::vector<StoredScan> scans_;  // `placed` where the points in placed_ are
  // Each scan's points in the map frame, in the order of scans_: shared with the encoder
  // thread, never copied whole.
  std::vector<std::shared_ptr<const PointCloud>> placed_;
  std::vector<std::uint8_t> in_map_;  // per scan: shown (not waiting outside the map)
  std::vector<std::string> outside_;  // per scan: why it waits outside the map (Followed)
  std::size_t point_count_ = 0;
  Bounds3 bounds_;  // of all points, kept as scans arrive: the session endpoint is polled often
  std::shared_ptr<const std::string> encoded_;  // the whole map up to encoded_last_scan_
  std::int64_t encoded_last_scan_ = 0;
  // Counts every change of the map's scans (a scan joined, the map rebuilt); the encoder
  // catches up with it while someone waits in encoded_map() (encode_waiters_), not after every
  // scan: the whole map is seconds of CPU at millions of points, which the next scan's match and
  // plan need on a 2-core laptop, and clients fetch scans one by one (?since, ?until).
  std::uint64_t generation_ = 0;
  std::uint64_t encoded_generation_ = 0;
  mutable int encode_waiters_ = 0;                   // with mutex_
  mutable std::condition_variable encoded_changed_;  // with mutex_
  mutable std::condition_variable encode_wanted_;    // with mutex_
  bool stopping_ = false;
  VoxelMap thinned_{kThinnedMapVoxelM};  // under encode_mutex_
  // By scan id; null until made (encoded_chunk) after the scan moved.
  mutable std::map<std::int64_t, std::shared_ptr<const std::string>> chunks_;
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> layers_;
  MapAreas areas_;
  std::map<std::int64_t, MapAreas> areas_after_;  // by scan id
  std::optional<LayerGeometry> layer_geometry_;
  std::optional<HeightRange> elevation_range_;  // of the elevation layer in layers_
  MissionPipeline mission_;                     // written only under encode_mutex_
  const double sensor_height_m_;
  std::pair<std::int64_t, std::string> last_scan_;  // id and robot; under encode_mutex_
  std::map<std::string, Pose> scan_pose_of_;  // each robot's last scan pose; under encode_mutex_
  PlanBook& plans_;
  std::atomic<double> claim_separation_m_;
  mutable std::mutex encode_mutex_;  // one writer at a time; readers keep the previous result
  std::thread encoder_;              // last member: starts once everything else exists

  // The encoder thread: encodes the whole map whenever a scan has joined since the last time
  // (several scans that arrived meanwhile in one go).
  void encode_loop();

  // The map's scans as mission_ has them now: each scan's pose, points (re-placed only when
  // it moved past MissionConfig::replace_m / _deg: smaller moves are invisible at the map's
  // scale and would re-send every chunk after every scan) and whether it is in the map.
  // Needs encode_mutex_ held; `scans` are the scans in mission_'s order.
  struct Followed {
    std::vector<StoredScan> scans;
    std::vector<std::shared_ptr<const PointCloud>> placed;
    std::vector<std::uint8_t> in_map;
    std::vector<std::string> outside;  // per scan: why not in the map (empty when in it)
    std::vector<Bounds3> bounds;
    std::vector<std::int64_t> unencoded;  // ids whose chunk must be made anew
    MapCorrected corrected;
  };
  // The last of `scans` just joined (its moves are not corrections).
  Followed follow_mission(std::vector<StoredScan> scans,
                          std::vector<std::shared_ptr<const PointCloud>> placed,
                          std::vector<std::uint8_t> in_map) const;
  // Where each robot is planned from, as `f` has the scans. Needs encode_mutex_ held.
  void follow_robots(const Followed& f);
  // The thinned map of the scans in `f` that are in the map: made anew when `whole` (it cannot
  // take a scan out), else the newest added. Needs encode_mutex_ held.
  void rethin(const Followed& f, bool whole);
  // Publishes `f`: scans, points, in-map flags, bounds and counts; the chunks of moved scans
  // are dropped to be made anew. Needs mutex_ and encode_mutex_ held.
  void commit(Followed f);
  std::vector<Bounds3> scan_bounds_;  // per scan, of placed_
  // Where scan `id` is in scans_. Needs mutex_ (or encode_mutex_) held.
  std::optional<std::size_t> index_of(std::int64_t id) const;

  // Recomputes layers, areas and the plans from the pipeline and publishes them together with
  // whatever `commit` changes (run under mutex_); needs encode_mutex_ held. Returns the new
  // plans, that of the robot whose scan came last last (none when there is no map to plan on).
  // `scan_joined`: the commit brings a new scan, whose areas after it are kept (areas_after).
  // `times`: the plans' and layers' time goes there.
  std::vector<PlanRecord> refresh_derived(const std::function<void()>& commit,
                                          bool scan_joined = true, AddTimes* times = nullptr);
  // One plan per robot not driving to a goal, the driving robots' goals claimed first; that of
  // the robot whose scan came last last. Needs encode_mutex_ held.
  std::vector<PlanRecord> make_plans() const;
  // The top-view layers of the map as it stands. Needs encode_mutex_ held.
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> render_layers() const;
};

}  // namespace scanplan::server

#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "bridge_liveness.hpp"
#include "events.hpp"
#include "scan_intake.hpp"
#include "scan_store.hpp"
#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::server {

class NoScannerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a bridge's loss cost: the scan it was taking (or whose parts were still arriving).
struct ScanLoss {
  std::uint32_t command_id = 0;  // 0 when only parts of an unrequested scan were in
  float fraction = 0;            // how far the scanner had got
  std::size_t parts_discarded = 0;
};

struct RobotLoss {
  std::string robot;
  std::string reason;   // why the server counts the bridge as gone
  std::string lost_at;  // UTC, ISO 8601
  std::optional<ScanLoss> scan;
};

// The server's side of DDS: receives scans, poses, panoramas, progress and status from bridges
// on its own thread, colourises each scan from its panorama and hands it to the store; sends
// commands on behalf of the API; publishes the map, the plan, the approved goal and the
// annotations to anyone (ROS 2 nodes included) on latched topics (docs/dds.md); watches each
// bridge's liveliness and, when one is lost, drops whatever of its scan had arrived so nothing
// half-received reaches the map.
class DdsLink {
 public:
  DdsLink(std::uint32_t domain_id, ScanStore& store, ScanIntake& intake, const Events& events);
  ~DdsLink();
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  void start();
  void stop();

  // Asks `robot_id` (empty: every robot) for one scan; returns the command id.
  // Throws NoScannerError when no bridge is listening for commands or that robot's is lost.
  std::uint32_t request_scan(const std::string& robot_id);
  // Sends `robot_id` to (x, y) facing yaw; returns the command id. Throws NoScannerError when no
  // bridge listens for move commands or that robot's is lost.
  std::uint32_t request_move(const std::string& robot_id, double x, double y, double yaw_deg);
  // Bridges currently subscribed to scan commands, less those whose liveliness was lost (DDS
  // keeps a killed bridge matched until its 10 s participant lease ends).
  int connected_bridges() const;
  // Server → anyone. Thread-safe; each logs rather than throws when DDS refuses the sample,
  // since what it announces is already stored and the caller's work must not fail over it.
  //
  // The thinned map in the map frame (PointCloud2, x y z float32 + rgb).
  void publish_map(const PointCloud& map_points);
  // The plan's candidates, best first, each facing the way the robot would arrive (PoseArray),
  // on rt/scanplan/candidates (the newest plan, whichever robot it is for) and on the robot's
  // own rt/<robot>/scanplan/candidates.
  void publish_candidates(const PlanRecord& plan);
  // Where the operator sent `robot` (PoseStamped), on rt/scanplan/goal and
  // rt/<robot>/scanplan/goal.
  void publish_goal(const std::string& robot, const Pose& goal);
  void publish_annotation(const Annotation& annotation);
  // Disposes and unregisters a deleted annotation, so late joiners no longer get it.
  void withdraw_annotation(std::int64_t id);

  // False once the robot's bridge is lost, until it (or a new one with its id) is back.
  bool robot_connected(const std::string& robot_id) const;

  // Called on the DDS thread (set before start()): every status a robot reports; a robot whose
  // bridge was lost, after its partial scan was discarded; a robot whose bridge is back.
  std::function<void(const std::string& robot, const RobotStatus& status)> on_status;
  std::function<void(const RobotLoss& loss)> on_robot_lost;
  std::function<void(const std::string& robot)> on_robot_back;

  // The reason a scan lost with its bridge is reported with.
  static constexpr const char* kScanLostReason = "bridge lost during the scan";

 private:
  // The parts of one scan, which travel on four topics and may arrive in any order.
  struct PartialScan {
    std::optional<PointCloud> points;
    std::optional<Pose> pose;
    std::optional<std::vector<std::uint8_t>> jpeg;
    std::optional<PanoramaCamera> camera;
    std::chrono::steady_clock::time_point first_seen = std::chrono::steady_clock::now();
  };
  using Key = std::pair<std::string, std::int64_t>;  // robot id, stamp

  // One liveliness change of one writer, as the listener saw it.
  struct LivelinessEvent {
    dds_entity_t reader;
    dds_instance_handle_t writer;
    bool alive;
    BridgeLiveness::Cause cause;
  };
  // A scan command sent and not yet settled, per robot: "requested", "scanning", "done".
  struct AwaitedScan {
    std::uint32_t command_id = 0;
    std::string state;
    float fraction = 0;
  };

  // Cyclone listener (its own threads): queues the change for the DDS thread.
  static void on_liveliness_changed(dds_entity_t reader, dds_liveliness_changed_status_t status,
                                    void* self);
  void apply_liveliness();
  void robot_changed(const BridgeLiveness::Change& change);
  void lose_robot(const std::string& robot, const std::string& reason);
  // Whether a sample comes from a bridge already counted as lost (taken after its lease ran out).
  bool from_lost_bridge(const dds_sample_info_t& info) const;
  // The parts of scan `key`, or null for a scan discarded with its bridge.
  PartialScan* part(const Key& key);
  // One robot's own latched topics (docs/dds.md "Several robots"), made on first use.
  struct RobotWriters {
    dds_entity_t candidates = 0, goal = 0;  // 0 where the id cannot name a topic
  };
  RobotWriters robot_writers(const std::string& robot);
  // Throws NoScannerError when `robot_id`'s bridge is lost.
  void require_connected(const std::string& robot_id) const;

  void loop();
  void take_samples();
  // Stores every scan whose points and pose are in, once its panorama is in too or it has
  // waited long enough for one (a robot without a camera, or a lost image).
  void complete_scans();
  void store_scan(const Key& key, PartialScan& scan);

  ScanStore& store_;
  ScanIntake& intake_;
  const Events& events_;
  // Declared before the participant so that they outlive its readers and their listener.
  std::mutex liveliness_queue_mutex_;
  std::vector<LivelinessEvent> liveliness_queue_;
  mutable std::mutex liveness_mutex_;
  BridgeLiveness liveness_;  // under liveness_mutex_
  dds::Participant participant_;
  dds_entity_t points_reader_, pose_reader_, image_reader_, camera_info_reader_, progress_reader_,
      status_reader_, scan_cmd_writer_, move_cmd_writer_, map_writer_, candidates_writer_,
      goal_writer_, annotation_writer_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex command_mutex_;
  std::uint32_t next_command_id_ = 1;
  std::map<Key, PartialScan> partial_;  // only touched by the DDS thread
  std::deque<Key> discarded_;           // scans dropped with their bridge; DDS thread only
  mutable std::mutex awaited_mutex_;
  std::map<std::string, AwaitedScan> awaited_;  // by robot, under awaited_mutex_
  std::mutex robot_writers_mutex_;
  std::map<std::string, RobotWriters> robot_writers_;  // under robot_writers_mutex_
};

}  // namespace scanplan::server

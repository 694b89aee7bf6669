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

#include "app/events.hpp"
#include "app/plan_book.hpp"
#include "app/robot_board.hpp"
#include "app/robot_link.hpp"
#include "app/scan_intake.hpp"
#include "dds/bridge_liveness.hpp"
#include "dds/scan_assembly.hpp"
#include "scanplan/geometry/panorama_camera.hpp"
#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::server {

// The server's side of DDS: receives scans, poses, panoramas, progress and status from bridges
// on its own thread, colourises each scan from its panorama and hands it to the store; sends
// commands on behalf of the API; publishes the map, the plan, the approved goal and the
// annotations to anyone (ROS 2 nodes included) on latched topics (docs/dds.md); watches each
// bridge's liveliness and, when one is lost, drops whatever of its scan had arrived so nothing
// half-received reaches the map.
class DdsLink final : public RobotLink, public AnnotationPublisher {
 public:
  DdsLink(std::uint32_t domain_id, RobotBoard& robots, ScanIntake& intake, const Events& events);
  ~DdsLink();
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  void start();
  void stop();

  // Asks `robot_id` (empty: every robot) for one scan; returns the command id.
  // Throws NoScannerError when no bridge is listening for commands or that robot's is lost.
  std::uint32_t request_scan(const std::string& robot_id) override;
  // Sends `robot_id` to (x, y) facing yaw; returns the command id. Throws NoScannerError when no
  // bridge listens for move commands or that robot's is lost.
  std::uint32_t request_move(const std::string& robot_id, double x, double y,
                             double yaw_deg) override;
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
  void publish_goal(const std::string& robot, const Pose& goal) override;
  void publish_annotation(const Annotation& annotation) override;
  // Disposes and unregisters a deleted annotation, so late joiners no longer get it.
  void withdraw_annotation(std::int64_t id) override;

  // False once the robot's bridge is lost, until it (or a new one with its id) is back.
  bool robot_connected(const std::string& robot_id) const;

  // Called on the DDS thread (set before start()): every status a robot reports; a robot whose
  // bridge was lost, after its partial scan was discarded; a robot whose bridge is back.
  std::function<void(const std::string& robot, const RobotStatus& status)> on_status;
  std::function<void(const RobotLoss& loss)> on_robot_lost;
  std::function<void(const std::string& robot)> on_robot_back;

 private:
  using Key = ScanAssembly::Key;

  // One liveliness change of one writer, as the listener saw it.
  struct LivelinessEvent {
    dds_entity_t reader;
    dds_instance_handle_t writer;
    bool alive;
    BridgeLiveness::Cause cause;
  };
  // A scan command sent and not yet settled, per robot: requested, scanning or done.
  struct AwaitedScan {
    std::uint32_t command_id = 0;
    ScanState state = ScanState::kRequested;
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
  // One robot's own latched topics (docs/dds.md "Several robots"), made on first use.
  struct RobotWriters {
    dds_entity_t candidates = 0, goal = 0;  // 0 where the id cannot name a topic
  };
  RobotWriters robot_writers(const std::string& robot);
  // Throws NoScannerError when `robot_id`'s bridge is lost.
  void require_connected(const std::string& robot_id) const;

  void loop();
  void take_samples();
  // Whether a sample's robot id is one (robot_id_problem); logs and drops it if not.
  static bool acceptable_robot_id(const std::string& robot);
  void take_progress();
  void take_status();
  // The four parts of scans, into the assembly.
  void take_scan_parts();
  // Stores every scan whose points and pose are in, once its panorama is in too or it has
  // waited long enough for one (a robot without a camera, or a lost image).
  void complete_scans();
  void store_scan(AssembledScan& scan);

  RobotBoard& robots_;
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
  ScanAssembly assembly_;  // only touched by the DDS thread
  mutable std::mutex awaited_mutex_;
  std::map<std::string, AwaitedScan> awaited_;  // by robot, under awaited_mutex_
  std::mutex robot_writers_mutex_;
  std::map<std::string, RobotWriters> robot_writers_;  // under robot_writers_mutex_
};

}  // namespace scanplan::server

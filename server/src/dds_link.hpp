#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "events.hpp"
#include "scan_intake.hpp"
#include "scan_store.hpp"
#include "scanplan/core/panorama_camera.hpp"
#include "scanplan/core/point_cloud.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::server {

class NoScannerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The server's side of DDS: receives scans, poses, panoramas, progress and status from bridges
// on its own thread, colourises each scan from its panorama and hands it to the store; sends
// commands on behalf of the API; publishes the map, the plan, the approved goal and the
// annotations to anyone (ROS 2 nodes included) on latched topics (docs/dds.md).
class DdsLink {
 public:
  DdsLink(std::uint32_t domain_id, ScanStore& store, ScanIntake& intake, const Events& events);
  ~DdsLink();
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  void start();
  void stop();

  // Asks `robot_id` (empty: every robot) for one scan; returns the command id.
  // Throws NoScannerError when no bridge is listening for commands.
  std::uint32_t request_scan(const std::string& robot_id);
  // Sends `robot_id` to (x, y) facing yaw; returns the command id. Throws NoScannerError when no
  // bridge listens for move commands.
  std::uint32_t request_move(const std::string& robot_id, double x, double y, double yaw_deg);
  // Bridges currently subscribed to scan commands.
  int connected_bridges() const;
  // Server → anyone. Thread-safe; each logs rather than throws when DDS refuses the sample,
  // since what it announces is already stored and the caller's work must not fail over it.
  //
  // The thinned map in the map frame (PointCloud2, x y z float32 + rgb).
  void publish_map(const PointCloud& map_points);
  // The plan's candidates, best first, each facing the way the robot would arrive (PoseArray).
  void publish_candidates(const PlanRecord& plan);
  // Where the operator sent a robot (PoseStamped).
  void publish_goal(const Pose& goal);
  void publish_annotation(const Annotation& annotation);
  // Disposes and unregisters a deleted annotation, so late joiners no longer get it.
  void withdraw_annotation(std::int64_t id);

  // Called on the DDS thread with every status a robot reports (set before start()).
  std::function<void(const std::string& robot, const RobotStatus& status)> on_status;

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

  void loop();
  void take_samples();
  // Stores every scan whose points and pose are in, once its panorama is in too or it has
  // waited long enough for one (a robot without a camera, or a lost image).
  void complete_scans();
  void store_scan(const Key& key, PartialScan& scan);

  ScanStore& store_;
  ScanIntake& intake_;
  const Events& events_;
  dds::Participant participant_;
  dds_entity_t points_reader_, pose_reader_, image_reader_, camera_info_reader_, progress_reader_,
      status_reader_, scan_cmd_writer_, move_cmd_writer_, map_writer_, candidates_writer_,
      goal_writer_, annotation_writer_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex command_mutex_;
  std::uint32_t next_command_id_ = 1;
  std::map<Key, PartialScan> partial_;  // only touched by the DDS thread
};

}  // namespace scanplan::server

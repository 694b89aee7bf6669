#pragma once

#include <atomic>
#include <cstdint>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <utility>

#include "scan_store.hpp"
#include "scanplan/core/point_cloud.hpp"
#include "scanplan/msgs/dds_participant.hpp"

namespace scanplan::server {

class NoScannerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The server's side of DDS: receives scans, poses and progress from bridges on its own thread
// and hands complete scans to the store; sends commands on behalf of the API.
class DdsLink {
 public:
  DdsLink(std::uint32_t domain_id, ScanStore& store);
  ~DdsLink();
  DdsLink(const DdsLink&) = delete;
  DdsLink& operator=(const DdsLink&) = delete;

  void start();
  void stop();

  // Asks `robot_id` (empty: every robot) for one scan; returns the command id.
  // Throws NoScannerError when no bridge is listening for commands.
  std::uint32_t request_scan(const std::string& robot_id);
  // Bridges currently subscribed to scan commands.
  int connected_bridges() const;

 private:
  void loop();
  void on_points(const std::string& robot, std::int64_t stamp, PointCloud cloud);
  void on_pose(const std::string& robot, std::int64_t stamp, const Pose& pose);
  void try_pair(const std::string& robot, std::int64_t stamp);

  ScanStore& store_;
  dds::Participant participant_;
  dds_entity_t points_reader_, pose_reader_, progress_reader_, scan_cmd_writer_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  std::mutex command_mutex_;
  std::uint32_t next_command_id_ = 1;

  // Points and pose of one scan travel on two topics and may arrive in either order; they are
  // paired by robot and stamp. Only touched by the DDS thread.
  using Key = std::pair<std::string, std::int64_t>;
  std::map<Key, PointCloud> pending_points_;
  std::map<Key, Pose> pending_poses_;
};

}  // namespace scanplan::server

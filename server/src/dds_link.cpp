#include "dds_link.hpp"

#include <spdlog/spdlog.h>

#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_stamped.hpp"
#include "scanplan/msgs/topics.hpp"

namespace scanplan::server {
namespace {

// A scan whose other half never comes (a bridge that died between the two writes) must not
// pin memory for the rest of the session.
constexpr std::size_t kMaxPending = 8;

template <typename Map>
void trim_oldest(Map& m) {
  while (m.size() > kMaxPending) m.erase(m.begin());
}

}  // namespace

DdsLink::DdsLink(std::uint32_t domain_id, ScanStore& store)
    : store_(store), participant_(domain_id) {
  points_reader_ = participant_.reader(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints,
                                       dds::QosKind::kScanData);
  pose_reader_ = participant_.reader(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose,
                                     dds::QosKind::kScanData);
  progress_reader_ = participant_.reader(scanplan_ScanProgress_desc, topics::kScanProgress,
                                         dds::QosKind::kStatus);
  scan_cmd_writer_ = participant_.writer(scanplan_ScanCommand_desc, topics::kScanCommand,
                                         dds::QosKind::kCommand);
}

DdsLink::~DdsLink() { stop(); }

void DdsLink::start() {
  thread_ = std::thread([this] { loop(); });
}

void DdsLink::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

std::uint32_t DdsLink::request_scan(const std::string& robot_id) {
  if (connected_bridges() == 0) {
    throw NoScannerError("no scanner bridge is connected on DDS; start scanplan-bridge");
  }
  std::lock_guard lock(command_mutex_);
  scanplan_ScanCommand cmd{};
  cmd.robot_id = const_cast<char*>(robot_id.c_str());
  cmd.command_id = next_command_id_++;
  dds::check(dds_write(scan_cmd_writer_, &cmd), "sending the scan command");
  return cmd.command_id;
}

int DdsLink::connected_bridges() const {
  dds_publication_matched_status_t st;
  dds::check(dds_get_publication_matched_status(scan_cmd_writer_, &st),
             "reading the command topic's matched status");
  return static_cast<int>(st.current_count);
}

void DdsLink::loop() {
  try {
    dds::ReadWaiter waiter(participant_.handle(), {points_reader_, pose_reader_, progress_reader_});
    while (!stop_) {
      if (!waiter.wait(std::chrono::milliseconds(100))) continue;
      dds::take_all<scanplan_ScanProgress>(progress_reader_, [&](const scanplan_ScanProgress& p) {
        store_.set_robot_state(p.robot_id ? p.robot_id : "",
                               {p.command_id, p.state ? p.state : "", p.fraction,
                                p.message ? p.message : ""});
      });
      dds::take_all<geometry_msgs_msg_dds__PoseStamped_>(
          pose_reader_, [&](const geometry_msgs_msg_dds__PoseStamped_& m) {
            on_pose(dds::robot_id_of(m.header.frame_id), dds::stamp_ns(m.header.stamp),
                    dds::from_pose_stamped(m));
          });
      dds::take_all<sensor_msgs_msg_dds__PointCloud2_>(
          points_reader_, [&](const sensor_msgs_msg_dds__PointCloud2_& m) {
            const std::string robot = dds::robot_id_of(m.header.frame_id);
            try {
              on_points(robot, dds::stamp_ns(m.header.stamp), dds::unpack_pointcloud2(m));
            } catch (const dds::PointCloud2Error& e) {
              spdlog::warn("discarding a scan from '{}': {}", robot, e.what());
            }
          });
    }
  } catch (const std::exception& e) {
    // Without DDS the session cannot receive scans, but the operator can still see the map.
    spdlog::error("DDS receive loop stopped: {}", e.what());
  }
}

void DdsLink::on_points(const std::string& robot, std::int64_t stamp, PointCloud cloud) {
  pending_points_[{robot, stamp}] = std::move(cloud);
  trim_oldest(pending_points_);
  try_pair(robot, stamp);
}

void DdsLink::on_pose(const std::string& robot, std::int64_t stamp, const Pose& pose) {
  pending_poses_[{robot, stamp}] = pose;
  trim_oldest(pending_poses_);
  try_pair(robot, stamp);
}

void DdsLink::try_pair(const std::string& robot, std::int64_t stamp) {
  const Key key{robot, stamp};
  auto p = pending_points_.find(key);
  auto q = pending_poses_.find(key);
  if (p == pending_points_.end() || q == pending_poses_.end()) return;
  try {
    const ScanRecord r = store_.add(robot, q->second, stamp, p->second);
    spdlog::info("scan {} from '{}': {} points at ({:.2f}, {:.2f}, {:.2f})", r.id, robot, r.points,
                 r.pose.x, r.pose.y, r.pose.z);
  } catch (const std::exception& e) {
    spdlog::error("could not store a scan from '{}': {}", robot, e.what());
  }
  pending_points_.erase(p);
  pending_poses_.erase(q);
}

}  // namespace scanplan::server

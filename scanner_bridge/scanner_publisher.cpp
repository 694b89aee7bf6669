#include "scanner_publisher.hpp"

#include <chrono>

#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/msgs/camera_info.hpp"
#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_stamped.hpp"
#include "scanplan/msgs/topics.hpp"

namespace scanplan::bridge {
namespace {

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

char* c_str(const std::string& s) {
  return const_cast<char*>(s.c_str());
}

}  // namespace

ScannerPublisher::ScannerPublisher(dds::Participant& p, std::string robot_id)
    : robot_id_(std::move(robot_id)) {
  using dds::QosKind;
  points_ = p.writer(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints, QosKind::kScanData);
  pose_ = p.writer(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose, QosKind::kScanData);
  image_ = p.writer(sensor_msgs_msg_dds__CompressedImage__desc, topics::kImage, QosKind::kScanData);
  camera_info_ =
      p.writer(sensor_msgs_msg_dds__CameraInfo__desc, topics::kCameraInfo, QosKind::kScanData);
  progress_ = p.writer(scanplan_ScanProgress_desc, topics::kScanProgress, QosKind::kStatus);
  status_ = p.writer(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus);
}

void ScannerPublisher::progress(std::uint32_t command_id, const std::string& state, float fraction,
                                const std::string& message) {
  scanplan_ScanProgress m{};
  m.robot_id = c_str(robot_id_);
  m.command_id = command_id;
  m.state = c_str(state);
  m.fraction = fraction;
  m.message = c_str(message);
  dds::check(dds_write(progress_, &m), "publishing scan progress");
}

void ScannerPublisher::status(std::uint32_t command_id, const std::string& state,
                              const Pose& reported, const std::string& message) {
  scanplan_RobotStatus m{};
  m.robot_id = c_str(robot_id_);
  m.command_id = command_id;
  m.state = c_str(state);
  m.message = c_str(message);
  m.x = reported.x;
  m.y = reported.y;
  m.z = reported.z;
  m.yaw_deg = rad2deg(reported.yaw);
  dds::check(dds_write(status_, &m), "publishing robot status");
}

void ScannerPublisher::goodbye(const Pose& reported) {
  status(0, "offline", reported, "scanplan-bridge was stopped");
  // Cyclone lingers on deleting a reliable writer until its data is acknowledged (up to 1 s),
  // so the goodbye reaches the server before the participant disappears.
}

void ScannerPublisher::scan(const PointCloud& cloud, const Pose& reported,
                            const std::optional<CameraShot>& shot) {
  const std::int64_t stamp = now_ns();
  if (shot) {
    dds::OwnedCameraInfo info;
    dds::to_camera_info(shot->camera, robot_id_ + "/camera", stamp, info);
    dds::check(dds_write(camera_info_, &info.msg), "publishing camera info");
    dds::OwnedCompressedImage image;
    image.frame_id = robot_id_ + "/camera";
    image.data = shot->jpeg;
    image.bind(stamp);
    dds::check(dds_write(image_, &image.msg), "publishing the panorama");
  }
  dds::OwnedPoseStamped pose;
  dds::to_pose_stamped(reported, robot_id_ + "/map", stamp, pose);
  dds::check(dds_write(pose_, &pose.msg), "publishing the scan pose");
  const dds::PackedPointCloud2 points(cloud, robot_id_ + "/scanner", stamp);
  dds::check(dds_write(points_, &points.msg()), "publishing the scan points");
}

}  // namespace scanplan::bridge

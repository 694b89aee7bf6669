#include "simulated_robot.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/core/simulated_scanner.hpp"
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

}  // namespace

SimulatedRobot::SimulatedRobot(World world, dds::Participant& participant, BridgeOptions options)
    : world_(std::move(world)),
      caster_(world_),
      participant_(participant),
      options_(std::move(options)),
      true_pose_(world_.start),
      pose_rng_(options_.seed) {
  scan_cmd_reader_ = participant_.reader(scanplan_ScanCommand_desc, topics::kScanCommand,
                                         dds::QosKind::kCommand);
  points_writer_ = participant_.writer(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints,
                                       dds::QosKind::kScanData);
  pose_writer_ = participant_.writer(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose,
                                     dds::QosKind::kScanData);
  progress_writer_ = participant_.writer(scanplan_ScanProgress_desc, topics::kScanProgress,
                                         dds::QosKind::kStatus);
}

void SimulatedRobot::run(const std::atomic<bool>& stop) {
  dds::ReadWaiter waiter(participant_.handle(), {scan_cmd_reader_});
  spdlog::info("robot '{}' ready in world '{}' at ({:.2f}, {:.2f}), waiting for commands",
               options_.robot_id, world_.name, true_pose_.x, true_pose_.y);
  while (!stop) {
    if (!waiter.wait(std::chrono::milliseconds(200))) continue;
    std::vector<std::uint32_t> commands;
    dds::take_all<scanplan_ScanCommand>(scan_cmd_reader_, [&](const scanplan_ScanCommand& c) {
      const std::string target = c.robot_id ? c.robot_id : "";
      if (target.empty() || target == options_.robot_id) commands.push_back(c.command_id);
    });
    for (const std::uint32_t id : commands) {
      if (stop) break;
      scan(id, stop);
    }
  }
}

void SimulatedRobot::publish_progress(std::uint32_t command_id, const std::string& state,
                                      float fraction, const std::string& message) {
  scanplan_ScanProgress p{};
  p.robot_id = const_cast<char*>(options_.robot_id.c_str());
  p.command_id = command_id;
  p.state = const_cast<char*>(state.c_str());
  p.fraction = fraction;
  p.message = const_cast<char*>(message.c_str());
  dds::check(dds_write(progress_writer_, &p), "publishing scan progress");
}

void SimulatedRobot::scan(std::uint32_t command_id, const std::atomic<bool>& stop) {
  spdlog::info("scan command {}: scanning", command_id);
  publish_progress(command_id, "scanning", 0.0f, "");
  const auto started = std::chrono::steady_clock::now();
  // The rotation stage takes scan_duration_s of simulated time; pacing the progress callback
  // against the wall clock makes the operator's progress bar move as the real scanner would.
  const double wall_duration_s =
      options_.time_scale > 0 ? world_.scanner.scan_duration_s / options_.time_scale : 0.0;
  float last_reported = 0.0f;
  const auto progress = [&](double fraction) {
    const auto due = started + std::chrono::duration<double>(wall_duration_s * fraction);
    std::this_thread::sleep_until(due);
    if (fraction - last_reported >= 0.01 || fraction >= 1.0) {
      last_reported = static_cast<float>(fraction);
      publish_progress(command_id, "scanning", last_reported, "");
    }
    return !stop.load();
  };
  const std::uint64_t seed = options_.seed * 1000003u + scans_taken_++;
  PointCloud cloud = simulate_scan(caster_, world_.scanner, true_pose_, seed, progress);
  if (stop) {
    publish_progress(command_id, "failed", last_reported, "the scanner was shut down mid-scan");
    return;
  }
  const Pose reported = reported_pose(true_pose_, world_.pose_noise, pose_rng_);
  const std::int64_t stamp = now_ns();
  // The pose goes first: the server pairs a scan with the pose of the same stamp.
  dds::OwnedPoseStamped pose_msg;
  dds::to_pose_stamped(reported, options_.robot_id + "/map", stamp, pose_msg);
  dds::check(dds_write(pose_writer_, &pose_msg.msg), "publishing the scan pose");
  const dds::PackedPointCloud2 points(cloud, options_.robot_id + "/scanner", stamp);
  dds::check(dds_write(points_writer_, &points.msg()), "publishing the scan points");
  publish_progress(command_id, "done", 1.0f, std::to_string(cloud.size()) + " points");
  spdlog::info("scan command {}: published {} points", command_id, cloud.size());
}

}  // namespace scanplan::bridge

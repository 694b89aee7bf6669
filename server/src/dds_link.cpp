#include "dds_link.hpp"

#include <spdlog/spdlog.h>

#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/core/colorizer.hpp"
#include "scanplan/core/image_codec.hpp"
#include "scanplan/msgs/camera_info.hpp"
#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_array.hpp"
#include "scanplan/msgs/pose_stamped.hpp"
#include "scanplan/msgs/topics.hpp"

namespace scanplan::server {
namespace {

// A scan whose other parts never come (a bridge that died between writes) must not pin memory
// for the rest of the session.
constexpr std::size_t kMaxPartial = 8;
constexpr auto kImageWait = std::chrono::seconds(2);
constexpr auto kPartialExpiry = std::chrono::seconds(60);

std::string str(const char* s) {
  return s ? s : "";
}

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

DdsLink::DdsLink(std::uint32_t domain_id, ScanStore& store, ScanIntake& intake,
                 const Events& events)
    : store_(store), intake_(intake), events_(events), participant_(domain_id) {
  using dds::QosKind;
  auto& p = participant_;
  points_reader_ =
      p.reader(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints, QosKind::kScanData);
  pose_reader_ =
      p.reader(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose, QosKind::kScanData);
  image_reader_ =
      p.reader(sensor_msgs_msg_dds__CompressedImage__desc, topics::kImage, QosKind::kScanData);
  camera_info_reader_ =
      p.reader(sensor_msgs_msg_dds__CameraInfo__desc, topics::kCameraInfo, QosKind::kScanData);
  progress_reader_ = p.reader(scanplan_ScanProgress_desc, topics::kScanProgress, QosKind::kStatus);
  status_reader_ = p.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus);
  scan_cmd_writer_ = p.writer(scanplan_ScanCommand_desc, topics::kScanCommand, QosKind::kCommand);
  move_cmd_writer_ = p.writer(scanplan_MoveCommand_desc, topics::kMoveCommand, QosKind::kCommand);
  // Latched (reliable, keep last 1, transient-local): each new map, plan or goal supersedes the
  // last, and a viewer or ROS node that joins mid-mission must get the current one without
  // waiting for the next scan or approval, which may be minutes away.
  map_writer_ = p.writer(sensor_msgs_msg_dds__PointCloud2__desc, topics::kMap, QosKind::kLatched);
  candidates_writer_ =
      p.writer(geometry_msgs_msg_dds__PoseArray__desc, topics::kCandidates, QosKind::kLatched);
  goal_writer_ =
      p.writer(geometry_msgs_msg_dds__PoseStamped__desc, topics::kGoal, QosKind::kLatched);
  // Keyed by id, so keep-last 1 is per annotation: a late joiner gets every live one.
  annotation_writer_ = p.writer(scanplan_Annotation_desc, topics::kAnnotation, QosKind::kLatched);
}

DdsLink::~DdsLink() {
  stop();
}

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

std::uint32_t DdsLink::request_move(const std::string& robot_id, double x, double y,
                                    double yaw_deg) {
  dds_publication_matched_status_t st;
  dds::check(dds_get_publication_matched_status(move_cmd_writer_, &st), "reading matched status");
  if (st.current_count == 0) {
    throw NoScannerError("no robot bridge is connected on DDS to take the move command");
  }
  std::lock_guard lock(command_mutex_);
  scanplan_MoveCommand cmd{};
  cmd.robot_id = const_cast<char*>(robot_id.c_str());
  cmd.command_id = next_command_id_++;
  cmd.x = x;
  cmd.y = y;
  cmd.yaw_deg = yaw_deg;
  dds::check(dds_write(move_cmd_writer_, &cmd), "sending the move command");
  return cmd.command_id;
}

void DdsLink::publish_map(const PointCloud& map_points) {
  try {
    const dds::PackedPointCloud2 msg(map_points, topics::kMapFrame, now_ns());
    dds::check(dds_write(map_writer_, &msg.msg()),
               "publishing the map on " + std::string(topics::kMap));
  } catch (const std::exception& e) {
    spdlog::error("the map ({} points) was not published: {}", map_points.size(), e.what());
  }
}

void DdsLink::publish_candidates(const PlanRecord& plan) {
  try {
    std::vector<Pose> poses;
    for (const CandidateRecord& r : plan.candidates) {
      Pose p;
      p.x = r.candidate.position.x();
      p.y = r.candidate.position.y();
      p.z = r.candidate.position.z();
      p.yaw = deg2rad(approach_yaw_deg(r.candidate));
      poses.push_back(p);
    }
    dds::OwnedPoseArray msg;
    dds::to_pose_array(poses, topics::kMapFrame, now_ns(), msg);
    dds::check(dds_write(candidates_writer_, &msg.msg),
               "publishing the candidates on " + std::string(topics::kCandidates));
  } catch (const std::exception& e) {
    spdlog::error("the candidates of plan {} were not published: {}", plan.id, e.what());
  }
}

void DdsLink::publish_goal(const Pose& goal) {
  try {
    dds::OwnedPoseStamped msg;
    dds::to_pose_stamped(goal, topics::kMapFrame, now_ns(), msg);
    dds::check(dds_write(goal_writer_, &msg.msg),
               "publishing the goal on " + std::string(topics::kGoal));
  } catch (const std::exception& e) {
    spdlog::error("the goal ({:.2f}, {:.2f}) was not published: {}", goal.x, goal.y, e.what());
  }
}

void DdsLink::publish_annotation(const Annotation& a) {
  try {
    scanplan_Annotation msg{};
    msg.id = a.id;
    msg.kind = const_cast<char*>(a.kind.c_str());
    msg.position = {a.x, a.y, a.z};
    msg.text = const_cast<char*>(a.text.c_str());
    msg.author = const_cast<char*>(a.author.c_str());
    msg.stamp = dds::to_stamp(a.created_ns);
    dds::check(dds_write(annotation_writer_, &msg),
               "publishing annotation " + std::to_string(a.id));
  } catch (const std::exception& e) {
    spdlog::error("annotation {} was not published: {}", a.id, e.what());
  }
}

void DdsLink::withdraw_annotation(std::int64_t id) {
  try {
    scanplan_Annotation key{};
    key.id = id;
    key.kind = key.text = key.author = const_cast<char*>("");
    // Disposed: readers learn it is gone. Unregistered: the writer drops the instance from the
    // history it keeps for late joiners.
    dds::check(dds_dispose(annotation_writer_, &key), "disposing annotation " + std::to_string(id));
    dds::check(dds_unregister_instance(annotation_writer_, &key),
               "unregistering annotation " + std::to_string(id));
  } catch (const std::exception& e) {
    spdlog::error("the deletion of annotation {} was not published: {}", id, e.what());
  }
}

int DdsLink::connected_bridges() const {
  dds_publication_matched_status_t st;
  dds::check(dds_get_publication_matched_status(scan_cmd_writer_, &st),
             "reading the command topic's matched status");
  return static_cast<int>(st.current_count);
}

void DdsLink::loop() {
  try {
    dds::ReadWaiter waiter(participant_.handle(),
                           {points_reader_, pose_reader_, image_reader_, camera_info_reader_,
                            progress_reader_, status_reader_});
    while (!stop_) {
      if (waiter.wait(std::chrono::milliseconds(100))) take_samples();
      complete_scans();
    }
  } catch (const std::exception& e) {
    // Without DDS the session cannot receive scans, but the operator can still see the map.
    spdlog::error("DDS receive loop stopped: {}", e.what());
  }
}

void DdsLink::take_samples() {
  dds::take_all<scanplan_ScanProgress>(progress_reader_, [&](const scanplan_ScanProgress& p) {
    store_.set_scan_state(str(p.robot_id),
                          {p.command_id, str(p.state), p.fraction, str(p.message)});
    events_.publish("scan_progress", {{"robot", str(p.robot_id)},
                                      {"command_id", p.command_id},
                                      {"state", str(p.state)},
                                      {"fraction", p.fraction},
                                      {"message", str(p.message)}});
  });
  dds::take_all<scanplan_RobotStatus>(status_reader_, [&](const scanplan_RobotStatus& s) {
    Pose pose;
    pose.x = s.x;
    pose.y = s.y;
    pose.z = s.z;
    pose.yaw = deg2rad(s.yaw_deg);
    const RobotStatus status{s.command_id, str(s.state), str(s.message), pose};
    store_.set_robot_status(str(s.robot_id), status);
    // The once-a-second idle heartbeat is not news.
    if (status.state != "idle" || status.command_id != 0) {
      events_.publish("robot_status",
                      {{"robot", str(s.robot_id)},
                       {"command_id", s.command_id},
                       {"state", status.state},
                       {"message", status.message},
                       {"pose", {{"x", s.x}, {"y", s.y}, {"z", s.z}, {"yaw_deg", s.yaw_deg}}}});
    }
    if (on_status) on_status(str(s.robot_id), status);
  });
  const auto key_of = [](const std_msgs_msg_dds__Header_& h) {
    return Key{dds::robot_id_of(h.frame_id), dds::stamp_ns(h.stamp)};
  };
  dds::take_all<sensor_msgs_msg_dds__CameraInfo_>(
      camera_info_reader_, [&](const sensor_msgs_msg_dds__CameraInfo_& m) {
        try {
          partial_[key_of(m.header)].camera = dds::from_camera_info(m);
        } catch (const dds::CameraInfoError& e) {
          spdlog::warn("ignoring camera info from '{}': {}", key_of(m.header).first, e.what());
        }
      });
  dds::take_all<sensor_msgs_msg_dds__CompressedImage_>(
      image_reader_, [&](const sensor_msgs_msg_dds__CompressedImage_& m) {
        partial_[key_of(m.header)].jpeg.emplace(m.data._buffer, m.data._buffer + m.data._length);
      });
  dds::take_all<geometry_msgs_msg_dds__PoseStamped_>(
      pose_reader_, [&](const geometry_msgs_msg_dds__PoseStamped_& m) {
        partial_[key_of(m.header)].pose = dds::from_pose_stamped(m);
      });
  dds::take_all<sensor_msgs_msg_dds__PointCloud2_>(
      points_reader_, [&](const sensor_msgs_msg_dds__PointCloud2_& m) {
        const Key key = key_of(m.header);
        try {
          partial_[key].points = dds::unpack_pointcloud2(m);
        } catch (const dds::PointCloud2Error& e) {
          spdlog::warn("discarding a scan from '{}': {}", key.first, e.what());
        }
      });
}

void DdsLink::complete_scans() {
  const auto now = std::chrono::steady_clock::now();
  for (auto it = partial_.begin(); it != partial_.end();) {
    PartialScan& s = it->second;
    const bool has_image = s.jpeg && s.camera;
    if (s.points && s.pose && (has_image || now - s.first_seen > kImageWait)) {
      store_scan(it->first, s);
      it = partial_.erase(it);
    } else if (now - s.first_seen > kPartialExpiry) {
      spdlog::warn("dropping an incomplete scan from '{}' (points {}, pose {})", it->first.first,
                   s.points ? "in" : "missing", s.pose ? "in" : "missing");
      it = partial_.erase(it);
    } else {
      ++it;
    }
  }
  while (partial_.size() > kMaxPartial) partial_.erase(partial_.begin());
}

void DdsLink::store_scan(const Key& key, PartialScan& s) {
  const std::string& robot = key.first;
  PointCloud& cloud = *s.points;
  if (s.jpeg && s.camera) {
    try {
      const ColorizeStats stats = colorize(cloud, decode_image(*s.jpeg), *s.camera);
      spdlog::info("colourised {} of {} points ({} hidden from the camera)", stats.colored,
                   cloud.size(), stats.occluded);
    } catch (const std::exception& e) {
      spdlog::warn("scan from '{}' stays uncoloured: {}", robot, e.what());
    }
  } else if (!cloud.has_colors()) {
    spdlog::warn("scan from '{}' came without a panorama: stored uncoloured", robot);
  }
  try {
    const StoredScan r = intake_.submit(robot, *s.pose, key.second, std::move(cloud));
    spdlog::info("scan {} from '{}' stored: {} points", r.id, robot, r.points);
  } catch (const std::exception& e) {
    spdlog::error("could not store a scan from '{}': {}", robot, e.what());
  }
}

}  // namespace scanplan::server

#include "dds/dds_link.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <memory>

#include "app/domain_json.hpp"
#include "common/iso_time.hpp"
#include "common/text_fields.hpp"
#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/io/image_codec.hpp"
#include "scanplan/mapping/colorizer.hpp"
#include "scanplan/msgs/camera_info.hpp"
#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_array.hpp"
#include "scanplan/msgs/pose_stamped.hpp"
#include "scanplan/msgs/topics.hpp"

namespace scanplan::server {
namespace {

std::string str(const char* s) {
  return s ? s : "";
}

// A robot's message is a line or two on the operator's screen; more is cut (cleaned_text).
constexpr std::size_t kMaxRobotMessageBytes = 1000;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

struct ListenerDeleter {
  void operator()(dds_listener_t* l) const { dds_delete_listener(l); }
};

// The participant a matched writer belongs to: the bridge process, whose writers live and die
// together. A writer already gone stands for itself.
dds_instance_handle_t participant_of_publication(dds_entity_t reader,
                                                 dds_instance_handle_t writer) {
  dds_builtintopic_endpoint_t* e = dds_get_matched_publication_data(reader, writer);
  if (!e) return writer;
  const dds_instance_handle_t participant = e->participant_instance_handle;
  dds_builtintopic_free_endpoint(e);
  return participant;
}

}  // namespace

DdsLink::DdsLink(std::uint32_t domain_id, RobotBoard& robots, ScanIntake& intake,
                 const Events& events)
    : robots_(robots), intake_(intake), events_(events), participant_(domain_id) {
  using dds::QosKind;
  auto& p = participant_;
  // Every reader of bridge data requests the bridge lease (QosKind kScanData / kStatus) and
  // reports each writer's liveliness change here. A listener, not dds_get_liveliness_changed_
  // status from the waitset: that status sums up the changes since the last read and keeps only
  // the last writer's handle, and two bridges dying together must both be seen.
  const std::unique_ptr<dds_listener_t, ListenerDeleter> listener(dds_create_listener(this));
  if (!listener) throw dds::DdsError("creating the DDS liveliness listener failed");
  dds_lset_liveliness_changed(listener.get(), &DdsLink::on_liveliness_changed);
  const dds_listener_t* l = listener.get();
  points_reader_ =
      p.reader(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints, QosKind::kScanData, l);
  pose_reader_ =
      p.reader(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose, QosKind::kScanData, l);
  image_reader_ =
      p.reader(sensor_msgs_msg_dds__CompressedImage__desc, topics::kImage, QosKind::kScanData, l);
  camera_info_reader_ =
      p.reader(sensor_msgs_msg_dds__CameraInfo__desc, topics::kCameraInfo, QosKind::kScanData, l);
  progress_reader_ =
      p.reader(scanplan_ScanProgress_desc, topics::kScanProgress, QosKind::kStatus, l);
  status_reader_ = p.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kStatus, l);
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
  // Cyclone waits for a running callback before it detaches the listener, so none can touch
  // this object once it is being destroyed.
  for (const dds_entity_t r : {points_reader_, pose_reader_, image_reader_, camera_info_reader_,
                               progress_reader_, status_reader_}) {
    if (const dds_return_t rc = dds_set_listener(r, nullptr); rc < 0) {
      spdlog::warn("detaching the liveliness listener failed: {}", dds_strretcode(rc));
    }
  }
}

void DdsLink::start() {
  thread_ = std::thread([this] { loop(); });
}

void DdsLink::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void DdsLink::require_connected(const std::string& robot_id) const {
  if (robot_id.empty() || robot_connected(robot_id)) return;
  std::string since;
  const auto states = robots_.states();
  if (const auto it = states.find(robot_id); it != states.end()) {
    since = " at " + it->second.connection.lost_at + " (" + it->second.connection.reason + ")";
  }
  throw NoScannerError("robot '" + robot_id + "' is not connected: its bridge was lost" + since +
                       "; restart scanplan-bridge --robot-id " + robot_id +
                       " and try again once the robot is back");
}

bool DdsLink::robot_connected(const std::string& robot_id) const {
  std::lock_guard lock(liveness_mutex_);
  return liveness_.connected(robot_id);
}

std::uint32_t DdsLink::request_scan(const std::string& robot_id) {
  require_connected(robot_id);
  if (connected_bridges() == 0) {
    throw NoScannerError("no scanner bridge is connected on DDS; start scanplan-bridge");
  }
  std::uint32_t id = 0;
  {
    std::lock_guard lock(command_mutex_);
    scanplan_ScanCommand cmd{};
    cmd.robot_id = const_cast<char*>(robot_id.c_str());
    cmd.command_id = next_command_id_++;
    dds::check(dds_write(scan_cmd_writer_, &cmd), "sending the scan command");
    id = cmd.command_id;
  }
  // Every robot the command reaches owes a scan now; should its bridge die before the scan is
  // in, the scan is reported failed.
  std::vector<std::string> robots{robot_id};
  if (robot_id.empty()) {
    std::lock_guard lock(liveness_mutex_);
    robots = liveness_.connected_robots();
  }
  std::lock_guard lock(awaited_mutex_);
  for (const std::string& r : robots) awaited_[r] = {id, ScanState::kRequested, 0.0f};
  return id;
}

std::uint32_t DdsLink::request_move(const std::string& robot_id, double x, double y,
                                    double yaw_deg) {
  require_connected(robot_id);
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

DdsLink::RobotWriters DdsLink::robot_writers(const std::string& robot) {
  std::lock_guard lock(robot_writers_mutex_);
  if (const auto it = robot_writers_.find(robot); it != robot_writers_.end()) return it->second;
  RobotWriters w;
  const auto candidates = topics::robot_topic(robot, topics::kRobotCandidatesSuffix);
  const auto goal = topics::robot_topic(robot, topics::kRobotGoalSuffix);
  if (candidates && goal) {
    try {
      w.candidates = participant_.writer(geometry_msgs_msg_dds__PoseArray__desc, *candidates,
                                         dds::QosKind::kLatched);
      w.goal = participant_.writer(geometry_msgs_msg_dds__PoseStamped__desc, *goal,
                                   dds::QosKind::kLatched);
    } catch (const std::exception& e) {
      spdlog::error("robot '{}' gets no topics of its own: {}", robot, e.what());
      w = {};
    }
  } else {
    spdlog::warn(
        "robot id '{}' cannot name a ROS 2 namespace (a letter, then letters, digits, '_'): its "
        "plan and goal go out on the shared topics only",
        robot);
  }
  robot_writers_[robot] = w;
  return w;
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
    if (const dds_entity_t own = robot_writers(plan.robot).candidates) {
      dds::check(dds_write(own, &msg.msg), "publishing robot '" + plan.robot + "'s candidates");
    }
  } catch (const std::exception& e) {
    spdlog::error("the candidates of plan {} were not published: {}", plan.id, e.what());
  }
}

void DdsLink::publish_goal(const std::string& robot, const Pose& goal) {
  try {
    dds::OwnedPoseStamped msg;
    dds::to_pose_stamped(goal, topics::kMapFrame, now_ns(), msg);
    dds::check(dds_write(goal_writer_, &msg.msg),
               "publishing the goal on " + std::string(topics::kGoal));
    if (const dds_entity_t own = robot_writers(robot).goal) {
      dds::check(dds_write(own, &msg.msg), "publishing robot '" + robot + "'s goal");
    }
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
  std::vector<dds_instance_handle_t> readers(8);
  for (;;) {
    const dds_return_t n =
        dds::check(dds_get_matched_subscriptions(scan_cmd_writer_, readers.data(), readers.size()),
                   "listing the readers of the scan command topic");
    const bool complete = static_cast<std::size_t>(n) <= readers.size();
    readers.resize(static_cast<std::size_t>(n));
    if (complete) break;  // else more matched meanwhile: ask again with room for them
  }
  int count = 0;
  for (const dds_instance_handle_t r : readers) {
    dds_builtintopic_endpoint_t* e = dds_get_matched_subscription_data(scan_cmd_writer_, r);
    if (!e) continue;  // unmatched since the listing
    const dds_instance_handle_t participant = e->participant_instance_handle;
    dds_builtintopic_free_endpoint(e);
    std::lock_guard lock(liveness_mutex_);
    if (!liveness_.participant_lost(participant)) ++count;
  }
  return count;
}

void DdsLink::on_liveliness_changed(dds_entity_t reader, dds_liveliness_changed_status_t st,
                                    void* self) {
  LivelinessEvent e{reader, st.last_publication_handle, false,
                    BridgeLiveness::Cause::kLeaseExpired};
  if (st.alive_count_change > 0) {
    e.alive = true;  // new, or alive again (not_alive_count_change −1)
  } else if (st.alive_count_change < 0) {
    // Alive → not alive is an expired lease; alive → gone is a writer that left.
    e.cause = st.not_alive_count_change > 0 ? BridgeLiveness::Cause::kLeaseExpired
                                            : BridgeLiveness::Cause::kLeft;
  } else if (st.not_alive_count_change < 0) {
    e.cause = BridgeLiveness::Cause::kLeft;  // not alive → gone: the participant lease ended
  } else {
    return;
  }
  auto* link = static_cast<DdsLink*>(self);
  std::lock_guard lock(link->liveliness_queue_mutex_);
  link->liveliness_queue_.push_back(e);
}

void DdsLink::apply_liveliness() {
  std::vector<LivelinessEvent> events;
  {
    std::lock_guard lock(liveliness_queue_mutex_);
    events.swap(liveliness_queue_);
  }
  for (const LivelinessEvent& e : events) {
    std::optional<BridgeLiveness::Change> change;
    if (e.alive) {
      bool known = false;
      {
        std::lock_guard lock(liveness_mutex_);
        known = liveness_.knows_writer(e.writer);
      }
      const dds_instance_handle_t participant =
          known ? 0 : participant_of_publication(e.reader, e.writer);
      std::lock_guard lock(liveness_mutex_);
      change = liveness_.writer_alive(e.writer, participant);
    } else {
      std::lock_guard lock(liveness_mutex_);
      change = liveness_.writer_lost(e.writer, e.cause);
    }
    if (change) robot_changed(*change);
  }
}

bool DdsLink::from_lost_bridge(const dds_sample_info_t& info) const {
  std::lock_guard lock(liveness_mutex_);
  return liveness_.writer_from_lost_participant(info.publication_handle);
}

void DdsLink::robot_changed(const BridgeLiveness::Change& change) {
  if (!change.connected) {
    lose_robot(change.robot, change.reason);
    return;
  }
  spdlog::info("the bridge of robot '{}' is back", change.robot);
  robots_.set_connection(change.robot, RobotConnection{});
  if (on_robot_back) on_robot_back(change.robot);
}

void DdsLink::lose_robot(const std::string& robot, const std::string& reason) {
  RobotLoss loss{robot, reason, iso8601_utc_now(), std::nullopt};
  // Whatever of its scans has arrived can never be completed by this bridge.
  const std::size_t parts = assembly_.discard(robot);
  {
    std::lock_guard lock(awaited_mutex_);
    const auto it = awaited_.find(robot);
    // Done with nothing left in the assembly means the scan is in (or was never going to come).
    if (it != awaited_.end() && (it->second.state != ScanState::kDone || parts > 0)) {
      loss.scan = ScanLoss{it->second.command_id, it->second.fraction, parts};
    } else if (parts > 0) {
      loss.scan = ScanLoss{0, 1.0f, parts};
    }
    if (it != awaited_.end()) awaited_.erase(it);
  }
  robots_.set_connection(robot, RobotConnection{false, loss.lost_at, reason});
  if (loss.scan) {
    robots_.set_scan_state(
        robot, {loss.scan->command_id, ScanState::kFailed, loss.scan->fraction, kScanLostReason});
    spdlog::warn("robot '{}' lost: {}; scan command {} discarded ({} parts had arrived)", robot,
                 reason, loss.scan->command_id, loss.scan->parts_discarded);
  } else {
    spdlog::warn("robot '{}' lost: {}", robot, reason);
  }
  if (on_robot_lost) on_robot_lost(loss);
}

void DdsLink::loop() {
  try {
    dds::ReadWaiter waiter(participant_.handle(),
                           {points_reader_, pose_reader_, image_reader_, camera_info_reader_,
                            progress_reader_, status_reader_});
    while (!stop_) {
      // Samples before liveliness changes: what is in the readers was received before the
      // changes now queued (a lease runs out 2 s after the bridge's last packet), and a bridge's
      // goodbye must be read before DDS's news of its writers going. Samples of a bridge already
      // counted as lost are dropped (from_lost_bridge).
      if (waiter.wait(std::chrono::milliseconds(100))) take_samples();
      apply_liveliness();
      complete_scans();
    }
  } catch (const std::exception& e) {
    // Without DDS the session cannot receive scans, but the operator can still see the map.
    spdlog::error("DDS receive loop stopped: {}", e.what());
  }
}

void DdsLink::take_samples() {
  take_progress();
  take_status();
  take_scan_parts();
}

bool DdsLink::acceptable_robot_id(const std::string& robot) {
  const auto why = robot_id_problem(robot, "robot_id");
  if (!why) return true;
  // A broken or hostile participant: its samples would put a name on every operator's screen
  // and in the session that no robot can have (issue 16).
  spdlog::warn("ignoring a sample for robot id '{}': {}", robot.substr(0, 64), *why);
  return false;
}

void DdsLink::take_progress() {
  dds::take_all<scanplan_ScanProgress>(
      progress_reader_, [&](const scanplan_ScanProgress& p, const dds_sample_info_t& info) {
        if (from_lost_bridge(info)) return;
        const std::string robot = str(p.robot_id);
        if (!acceptable_robot_id(robot)) return;
        // A progress state this server does not know counts as the robot saying it failed.
        const ScanState state = parse_scan_state(str(p.state)).value_or(ScanState::kFailed);
        {
          std::lock_guard lock(awaited_mutex_);
          if (state == ScanState::kScanning || state == ScanState::kDone) {
            awaited_[robot] = {p.command_id, state, p.fraction};
          } else {
            awaited_.erase(robot);  // failed: the robot said so itself
          }
        }
        const RobotScanState scan{p.command_id, state, p.fraction,
                                  cleaned_text(str(p.message), kMaxRobotMessageBytes)};
        robots_.set_scan_state(robot, scan);
        events_.publish("scan_progress", scan_progress_json(robot, scan));
      });
}

void DdsLink::take_status() {
  dds::take_all<scanplan_RobotStatus>(
      status_reader_, [&](const scanplan_RobotStatus& s, const dds_sample_info_t& info) {
        if (from_lost_bridge(info)) return;
        const std::string robot = str(s.robot_id);
        if (!acceptable_robot_id(robot)) return;
        // The status names the robot the writer's participant (the bridge) speaks for.
        bool known = false;
        {
          std::lock_guard lock(liveness_mutex_);
          known = liveness_.knows_writer(info.publication_handle);
        }
        const dds_instance_handle_t participant =
            known ? 0 : participant_of_publication(status_reader_, info.publication_handle);
        std::optional<BridgeLiveness::Change> change;
        {
          std::lock_guard lock(liveness_mutex_);
          change = liveness_.announced(info.publication_handle, participant, robot);
        }
        if (change) robot_changed(*change);
        Pose pose;
        pose.x = s.x;
        pose.y = s.y;
        pose.z = s.z;
        pose.yaw = deg2rad(s.yaw_deg);
        const RobotStatus status{s.command_id, parse_robot_activity(str(s.state)),
                                 cleaned_text(str(s.message), kMaxRobotMessageBytes), pose};
        robots_.set_status(robot, status);
        // The once-a-second idle heartbeat is not news.
        if (status.state != RobotActivity::kIdle || status.command_id != 0) {
          events_.publish("robot_status", robot_status_json(robot, status));
        }
        if (on_status) on_status(robot, status);
        // The bridge's last word: published (as a status) before the robot is reported lost.
        if (status.state == RobotActivity::kOffline) {
          {
            std::lock_guard lock(liveness_mutex_);
            change = liveness_.said_goodbye(info.publication_handle);
          }
          if (change) robot_changed(*change);
        }
      });
}

void DdsLink::take_scan_parts() {
  const auto key_of = [](const std_msgs_msg_dds__Header_& h) {
    return Key{dds::robot_id_of(h.frame_id), dds::stamp_ns(h.stamp)};
  };
  const auto now = ScanAssembly::Clock::now();
  dds::take_all<sensor_msgs_msg_dds__CameraInfo_>(
      camera_info_reader_,
      [&](const sensor_msgs_msg_dds__CameraInfo_& m, const dds_sample_info_t& info) {
        if (from_lost_bridge(info)) return;
        try {
          assembly_.add_camera(key_of(m.header), dds::from_camera_info(m), now);
        } catch (const dds::CameraInfoError& e) {
          spdlog::warn("ignoring camera info from '{}': {}", key_of(m.header).first, e.what());
        }
      });
  dds::take_all<sensor_msgs_msg_dds__CompressedImage_>(
      image_reader_,
      [&](const sensor_msgs_msg_dds__CompressedImage_& m, const dds_sample_info_t& info) {
        if (from_lost_bridge(info)) return;
        assembly_.add_image(key_of(m.header), {m.data._buffer, m.data._buffer + m.data._length},
                            now);
      });
  dds::take_all<geometry_msgs_msg_dds__PoseStamped_>(
      pose_reader_,
      [&](const geometry_msgs_msg_dds__PoseStamped_& m, const dds_sample_info_t& info) {
        if (!from_lost_bridge(info))
          assembly_.add_pose(key_of(m.header), dds::from_pose_stamped(m), now);
      });
  dds::take_all<sensor_msgs_msg_dds__PointCloud2_>(
      points_reader_,
      [&](const sensor_msgs_msg_dds__PointCloud2_& m, const dds_sample_info_t& info) {
        if (from_lost_bridge(info)) return;
        const Key key = key_of(m.header);
        try {
          assembly_.add_points(key, dds::unpack_pointcloud2(m), now);
        } catch (const dds::PointCloud2Error& e) {
          spdlog::warn("discarding a scan from '{}': {}", key.first, e.what());
        }
      });
}

void DdsLink::complete_scans() {
  ScanAssembly::Taken taken = assembly_.take(ScanAssembly::Clock::now());
  for (const ScanAssembly::Dropped& d : taken.dropped) {
    spdlog::warn("dropping an incomplete scan from '{}' (points {}, pose {})", d.key.first,
                 d.had_points ? "in" : "missing", d.had_pose ? "in" : "missing");
  }
  for (AssembledScan& scan : taken.complete) store_scan(scan);
}

void DdsLink::store_scan(AssembledScan& s) {
  const std::string& robot = s.robot;
  PointCloud& cloud = s.points;
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
  {
    // The scan is in: a loss of the bridge from now on costs no scan. ("requested" is a newer
    // command, sent while this scan's parts were still being gathered.)
    std::lock_guard lock(awaited_mutex_);
    if (const auto it = awaited_.find(robot);
        it != awaited_.end() && it->second.state != ScanState::kRequested)
      awaited_.erase(it);
  }
  try {
    const StoredScan r = intake_.submit(robot, s.pose, s.stamp_ns, std::move(cloud)).scan;
    spdlog::info("scan {} from '{}' stored: {} points", r.id, robot, r.points);
  } catch (const std::exception& e) {
    spdlog::error("could not store a scan from '{}': {}", robot, e.what());
  }
}

}  // namespace scanplan::server

// A stand-in for a ROS 2 node on rmw_cyclonedds: a plain Cyclone DDS program that knows only the
// ROS 2 message types (compiled for this program from msgs/idl/ros2_types.idl, without the
// scanplan module or any scanplan code) and the ROS topic names. It subscribes to what the
// workstation shares with robots and prints one JSON line per sample, which
// tests/integration/ros_wire.test.mjs compares with the REST API:
//   rt/scanplan/map, rt/scanplan/candidates, rt/scanplan/goal (latched: asked for with
//   transient-local, as a late-joining ROS node would), rt/scanner/points and rt/scanner/pose
//   (ROS 2's default subscription QoS).
//   With --robots, each robot's own rt/<robot>/scanplan/candidates and rt/<robot>/scanplan/goal.
// Usage: ros_wire_listener --domain N [--seconds S] [--robots ID,ID]
#include <cmath>
#include <cstring>
#include <limits>

#include "dds_listener.hpp"
#include "ros2_types.h"

namespace {

using nlohmann::json;
using scanplan::test::check;

constexpr std::uint8_t kFloat32 = 7;  // sensor_msgs/PointField FLOAT32

json header_json(const std_msgs_msg_dds__Header_& h) {
  return {{"frame_id", h.frame_id ? h.frame_id : ""},
          {"stamp_ns", static_cast<std::int64_t>(h.stamp.sec) * 1000000000 + h.stamp.nanosec}};
}

json pose_json(const geometry_msgs_msg_dds__Pose_& p) {
  return {{"x", p.position.x},     {"y", p.position.y},     {"z", p.position.z},
          {"qx", p.orientation.x}, {"qy", p.orientation.y}, {"qz", p.orientation.z},
          {"qw", p.orientation.w}};
}

// Reads a PointCloud2 the way any ROS consumer must: by its field table, not by assumption.
json cloud_json(const char* topic, const sensor_msgs_msg_dds__PointCloud2_& m) {
  json out = header_json(m.header);
  out["topic"] = topic;
  json fields = json::array();
  int off[3] = {-1, -1, -1};
  int rgb = -1;
  for (std::uint32_t i = 0; i < m.fields._length; ++i) {
    const auto& f = m.fields._buffer[i];
    const std::string name = f.name ? f.name : "";
    fields.push_back(
        {{"name", name}, {"offset", f.offset}, {"datatype", f.datatype}, {"count", f.count}});
    if (f.datatype == kFloat32 && name.size() == 1 && name[0] >= 'x' && name[0] <= 'z') {
      off[name[0] - 'x'] = static_cast<int>(f.offset);
    }
    if (name == "rgb") rgb = static_cast<int>(f.offset);
  }
  out["fields"] = fields;
  out["width"] = m.width;
  out["height"] = m.height;
  out["point_step"] = m.point_step;
  out["row_step"] = m.row_step;
  out["is_bigendian"] = m.is_bigendian;
  const std::uint64_t n = std::uint64_t(m.width) * m.height;
  const bool sized = m.point_step >= 12 && std::uint64_t(m.row_step) * m.height <= m.data._length &&
                     std::uint64_t(m.point_step) * m.width <= m.row_step;
  out["consistent"] = sized && off[0] >= 0 && off[1] >= 0 && off[2] >= 0;
  if (!out["consistent"].get<bool>()) return out;
  float lo[3], hi[3];
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::numeric_limits<float>::max();
    hi[a] = std::numeric_limits<float>::lowest();
  }
  std::uint64_t finite = 0, colored = 0;
  for (std::uint32_t row = 0; row < m.height; ++row) {
    for (std::uint32_t col = 0; col < m.width; ++col) {
      const std::uint8_t* p =
          m.data._buffer + std::uint64_t(row) * m.row_step + std::uint64_t(col) * m.point_step;
      float v[3];
      for (int a = 0; a < 3; ++a) std::memcpy(&v[a], p + off[a], 4);
      if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) continue;
      ++finite;
      for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], v[a]), hi[a] = std::max(hi[a], v[a]);
      if (rgb >= 0) {
        std::uint32_t c;
        std::memcpy(&c, p + rgb, 4);
        colored += (c & 0xFFFFFFu) != 0;
      }
    }
  }
  out["points"] = n;
  out["finite"] = finite;
  out["colored"] = colored;
  if (finite > 0) {
    out["min"] = {lo[0], lo[1], lo[2]};
    out["max"] = {hi[0], hi[1], hi[2]};
  }
  return out;
}

dds_entity_t make_reader(dds_entity_t participant, const dds_topic_descriptor_t& type,
                         const char* name, dds_qos_t* qos) {
  const dds_entity_t topic = check(dds_create_topic(participant, &type, name, nullptr, nullptr),
                                   std::string("creating topic ") + name);
  const dds_entity_t r = dds_create_reader(participant, topic, qos, nullptr);
  dds_delete_qos(qos);
  return check(r, std::string("creating a reader for ") + name);
}

}  // namespace

int main(int argc, char** argv) {
  using namespace scanplan::test;
  try {
    const ListenerArgs args = parse_listener_args(argc, argv);
    const dds_entity_t participant =
        check(dds_create_participant(args.domain, nullptr, nullptr), "creating the participant");
    const auto cloud_sub = [&](const char* name, dds_qos_t* qos) {
      return Subscription{
          make_reader(participant, sensor_msgs_msg_dds__PointCloud2__desc, name, qos),
          [name](const void* s, const dds_sample_info_t& info) {
            if (!info.valid_data) return;
            emit(cloud_json(name, *static_cast<const sensor_msgs_msg_dds__PointCloud2_*>(s)));
          }};
    };
    const auto pose_sub = [&](const char* name, dds_qos_t* qos) {
      return Subscription{
          make_reader(participant, geometry_msgs_msg_dds__PoseStamped__desc, name, qos),
          [name](const void* s, const dds_sample_info_t& info) {
            if (!info.valid_data) return;
            const auto& m = *static_cast<const geometry_msgs_msg_dds__PoseStamped_*>(s);
            json out = header_json(m.header);
            out["topic"] = name;
            out["pose"] = pose_json(m.pose);
            emit(out);
          }};
    };
    const auto poses_sub = [&](const char* name, dds_qos_t* qos) {
      return Subscription{
          make_reader(participant, geometry_msgs_msg_dds__PoseArray__desc, name, qos),
          [name](const void* s, const dds_sample_info_t& info) {
            if (!info.valid_data) return;
            const auto& m = *static_cast<const geometry_msgs_msg_dds__PoseArray_*>(s);
            json out = header_json(m.header);
            out["topic"] = name;
            out["poses"] = json::array();
            for (std::uint32_t i = 0; i < m.poses._length; ++i) {
              out["poses"].push_back(pose_json(m.poses._buffer[i]));
            }
            emit(out);
          }};
    };
    std::vector<Subscription> subs = {
        cloud_sub("rt/scanplan/map", latched_reader_qos()),
        poses_sub("rt/scanplan/candidates", latched_reader_qos()),
        pose_sub("rt/scanplan/goal", latched_reader_qos()),
        cloud_sub("rt/scanner/points", ros_default_reader_qos()),
        pose_sub("rt/scanner/pose", ros_default_reader_qos()),
    };
    // Several robots: each one's own plan and goal under its ROS 2 namespace. The names must
    // outlive the subscriptions' callbacks.
    std::vector<std::string> names;
    names.reserve(2 * args.robots.size());
    for (const std::string& robot : args.robots) {
      names.push_back("rt/" + robot + "/scanplan/candidates");
      subs.push_back(poses_sub(names.back().c_str(), latched_reader_qos()));
      names.push_back("rt/" + robot + "/scanplan/goal");
      subs.push_back(pose_sub(names.back().c_str(), latched_reader_qos()));
    }
    run_listener(participant, subs, args.seconds);
    check(dds_delete(participant), "deleting the participant");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ros_wire_listener: %s\n", e.what());
    return 1;
  }
  return 0;
}

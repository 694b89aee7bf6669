#include "scanplan/msgs/pointcloud2.hpp"

#include <cmath>
#include <cstring>
#include <limits>

namespace scanplan::dds {
namespace {

constexpr std::uint8_t kFloat32 = 7;  // sensor_msgs/PointField FLOAT32
constexpr std::uint32_t kPointStep = 16;

}  // namespace

std::int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& t) {
  return static_cast<std::int64_t>(t.sec) * 1000000000 + t.nanosec;
}

builtin_interfaces_msg_dds__Time_ to_stamp(std::int64_t ns) {
  builtin_interfaces_msg_dds__Time_ t;
  t.sec = static_cast<std::int32_t>(ns / 1000000000);
  t.nanosec = static_cast<std::uint32_t>(ns % 1000000000);
  return t;
}

std::string robot_id_of(const char* frame_id) {
  const std::string f = frame_id ? frame_id : "";
  return f.substr(0, f.find('/'));
}

PackedPointCloud2::PackedPointCloud2(const PointCloud& cloud, const std::string& frame_id,
                                     std::int64_t stamp)
    : frame_id_(frame_id), names_{"x", "y", "z", "rgb"} {
  for (std::uint32_t i = 0; i < names_.size(); ++i) {
    fields_.push_back({names_[i].data(), 4 * i, kFloat32, 1});
  }
  const std::size_t n = cloud.size();
  data_.resize(n * kPointStep);
  const bool colored = cloud.has_colors();
  for (std::size_t i = 0; i < n; ++i) {
    std::uint8_t* p = data_.data() + i * kPointStep;
    std::memcpy(p, cloud.points[i].data(), 12);
    // ROS packs colour as 0x00RRGGBB reinterpreted as a float32; 0 stands for "not
    // colourised yet" (a laser alone sees no colour).
    const std::uint32_t rgb = colored ? (std::uint32_t(cloud.colors[i][0]) << 16) |
                                            (std::uint32_t(cloud.colors[i][1]) << 8) |
                                            cloud.colors[i][2]
                                      : 0u;
    std::memcpy(p + 12, &rgb, 4);
  }
  msg_.header.stamp = to_stamp(stamp);
  msg_.header.frame_id = frame_id_.data();
  msg_.height = 1;
  msg_.width = static_cast<std::uint32_t>(n);
  msg_.fields._maximum = msg_.fields._length = static_cast<std::uint32_t>(fields_.size());
  msg_.fields._buffer = fields_.data();
  msg_.fields._release = false;
  msg_.is_bigendian = false;
  msg_.point_step = kPointStep;
  msg_.row_step = static_cast<std::uint32_t>(n * kPointStep);
  msg_.data._maximum = msg_.data._length = static_cast<std::uint32_t>(data_.size());
  msg_.data._buffer = data_.data();
  msg_.data._release = false;
  msg_.is_dense = true;
}

PointCloud unpack_pointcloud2(const sensor_msgs_msg_dds__PointCloud2_& msg) {
  if (msg.is_bigendian) throw PointCloud2Error("big-endian PointCloud2 is not supported");
  const std::uint64_t count = std::uint64_t(msg.width) * msg.height;
  if (msg.point_step == 0 && count > 0) throw PointCloud2Error("point_step is zero");
  if (std::uint64_t(msg.point_step) * msg.width > msg.row_step) {
    throw PointCloud2Error("row_step is smaller than width × point_step");
  }
  if (std::uint64_t(msg.row_step) * msg.height > msg.data._length) {
    throw PointCloud2Error("data holds " + std::to_string(msg.data._length) +
                           " bytes, fewer than row_step × height");
  }
  int off[3] = {-1, -1, -1};
  int rgb_off = -1;
  for (std::uint32_t i = 0; i < msg.fields._length; ++i) {
    const auto& f = msg.fields._buffer[i];
    const std::string name = f.name ? f.name : "";
    const bool fits = f.offset + 4 <= msg.point_step;
    if ((name == "x" || name == "y" || name == "z") && f.datatype == kFloat32 && fits) {
      off[name[0] - 'x'] = static_cast<int>(f.offset);
    } else if ((name == "rgb" || name == "rgba") && fits) {
      rgb_off = static_cast<int>(f.offset);
    }
  }
  if (off[0] < 0 || off[1] < 0 || off[2] < 0) {
    throw PointCloud2Error("PointCloud2 needs float32 fields x, y and z");
  }
  PointCloud cloud;
  cloud.reserve(count);
  bool any_color = false;
  for (std::uint32_t row = 0; row < msg.height; ++row) {
    const std::uint8_t* base = msg.data._buffer + std::uint64_t(row) * msg.row_step;
    for (std::uint32_t col = 0; col < msg.width; ++col) {
      const std::uint8_t* p = base + std::uint64_t(col) * msg.point_step;
      Eigen::Vector3f xyz;
      for (int a = 0; a < 3; ++a) std::memcpy(&xyz[a], p + off[a], 4);
      if (!xyz.allFinite()) continue;
      Rgb c{0, 0, 0};
      if (rgb_off >= 0) {
        std::uint32_t v;
        std::memcpy(&v, p + rgb_off, 4);
        c = {std::uint8_t(v >> 16), std::uint8_t(v >> 8), std::uint8_t(v)};
        any_color |= (v & 0xFFFFFFu) != 0;
      }
      cloud.push_back(xyz, c);
    }
  }
  if (!any_color) cloud.colors.clear();
  return cloud;
}

}  // namespace scanplan::dds

#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "ros2_types.h"
#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan::dds {

// A PointCloud2 message that borrows nothing: it owns the field list and the packed bytes the
// DDS sample points into, so the sample stays valid for as long as this object lives.
class PackedPointCloud2 {
 public:
  PackedPointCloud2(const PointCloud& cloud, const std::string& frame_id, std::int64_t stamp_ns);
  PackedPointCloud2(const PackedPointCloud2&) = delete;
  PackedPointCloud2& operator=(const PackedPointCloud2&) = delete;
  const sensor_msgs_msg_dds__PointCloud2_& msg() const { return msg_; }

 private:
  std::string frame_id_;
  std::vector<std::string> names_;
  std::vector<sensor_msgs_msg_dds__PointField_> fields_;
  std::vector<std::uint8_t> data_;
  sensor_msgs_msg_dds__PointCloud2_ msg_{};
};

class PointCloud2Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads x, y, z (float32) and, when present, ROS's packed `rgb`/`rgba` field from any
// PointCloud2 layout; non-finite points are dropped. A cloud whose colours are all 0 (not
// colourised) comes back without colours. Throws PointCloud2Error for a message
// whose sizes or fields do not add up.
PointCloud unpack_pointcloud2(const sensor_msgs_msg_dds__PointCloud2_& msg);

std::int64_t stamp_ns(const builtin_interfaces_msg_dds__Time_& t);
builtin_interfaces_msg_dds__Time_ to_stamp(std::int64_t ns);

// The robot id is the first part of header.frame_id ("robot1/scanner" → "robot1").
std::string robot_id_of(const char* frame_id);

}  // namespace scanplan::dds

#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "ros2_types.h"
#include "scanplan/geometry/pose.hpp"

namespace scanplan::dds {

// A PoseArray sample that owns its frame string and poses; the message points into them, so it
// stays valid for as long as this object lives and is not changed.
struct OwnedPoseArray {
  std::string frame_id;
  std::vector<geometry_msgs_msg_dds__Pose_> poses;
  geometry_msgs_msg_dds__PoseArray_ msg{};
};

void to_pose_array(const std::vector<Pose>& poses, const std::string& frame_id,
                   std::int64_t stamp_ns, OwnedPoseArray& out);

}  // namespace scanplan::dds

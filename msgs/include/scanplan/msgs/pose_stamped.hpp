#pragma once

#include <cstdint>
#include <string>

#include "ros2_types.h"
#include "scanplan/geometry/pose.hpp"

namespace scanplan::dds {

// A PoseStamped sample plus the frame string it points into.
struct OwnedPoseStamped {
  std::string frame_id;
  geometry_msgs_msg_dds__PoseStamped_ msg{};
};

// `out` keeps the frame string alive; the message points into it.
void to_pose_stamped(const Pose& pose, const std::string& frame_id, std::int64_t stamp_ns,
                     OwnedPoseStamped& out);
Pose from_pose_stamped(const geometry_msgs_msg_dds__PoseStamped_& msg);

}  // namespace scanplan::dds

#include "scanplan/msgs/pose_array.hpp"

#include "scanplan/msgs/pointcloud2.hpp"

namespace scanplan::dds {

void to_pose_array(const std::vector<Pose>& poses, const std::string& frame_id,
                   std::int64_t stamp_ns, OwnedPoseArray& out) {
  out.frame_id = frame_id;
  out.poses.clear();
  out.poses.reserve(poses.size());
  for (const Pose& p : poses) {
    const Eigen::Quaterniond q = p.orientation();
    out.poses.push_back({{p.x, p.y, p.z}, {q.x(), q.y(), q.z(), q.w()}});
  }
  out.msg.header.frame_id = out.frame_id.data();
  out.msg.header.stamp = to_stamp(stamp_ns);
  out.msg.poses._maximum = out.msg.poses._length = static_cast<std::uint32_t>(out.poses.size());
  out.msg.poses._buffer = out.poses.data();
  out.msg.poses._release = false;  // the vector owns the poses, not the DDS sample
}

}  // namespace scanplan::dds

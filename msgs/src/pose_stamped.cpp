#include "scanplan/msgs/pose_stamped.hpp"

#include "scanplan/msgs/pointcloud2.hpp"

namespace scanplan::dds {

void to_pose_stamped(const Pose& pose, const std::string& frame_id, std::int64_t stamp,
                     OwnedPoseStamped& out) {
  out.frame_id = frame_id;
  out.msg.header.frame_id = out.frame_id.data();
  out.msg.header.stamp = to_stamp(stamp);
  out.msg.pose.position = {pose.x, pose.y, pose.z};
  const Eigen::Quaterniond q = pose.orientation();
  out.msg.pose.orientation = {q.x(), q.y(), q.z(), q.w()};
}

Pose from_pose_stamped(const geometry_msgs_msg_dds__PoseStamped_& msg) {
  const auto& o = msg.pose.orientation;
  Eigen::Quaterniond q(o.w, o.x, o.y, o.z);
  // A zero quaternion (an unset orientation) reads as no rotation rather than NaNs.
  if (q.norm() < 1e-9) q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(msg.pose.position.x, msg.pose.position.y, msg.pose.position.z);
  return Pose::from_isometry(T);
}

}  // namespace scanplan::dds

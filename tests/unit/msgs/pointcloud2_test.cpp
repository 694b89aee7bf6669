#include <gtest/gtest.h>

#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_array.hpp"
#include "scanplan/msgs/pose_stamped.hpp"

namespace scanplan::dds {
namespace {

TEST(PointCloud2, PackUnpackKeepsPointsColoursAndHeader) {
  PointCloud in;
  in.push_back({1, 2, 3}, {10, 20, 30});
  in.push_back({-4.5f, 0.25f, 7}, {255, 0, 128});
  const PackedPointCloud2 packed(in, "robot7/scanner", 1'700'000'000'123'456'789);
  const auto& m = packed.msg();
  EXPECT_EQ(m.width, 2u);
  EXPECT_EQ(m.point_step, 16u);
  EXPECT_EQ(robot_id_of(m.header.frame_id), "robot7");
  EXPECT_EQ(stamp_ns(m.header.stamp), 1'700'000'000'123'456'789);
  const PointCloud out = unpack_pointcloud2(m);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out.points[1], in.points[1]);
  EXPECT_EQ(out.colors[1], in.colors[1]);
}

TEST(PointCloud2, NonFinitePointsAreDropped) {
  PointCloud in;
  in.push_back({1, 2, 3}, {1, 1, 1});
  in.push_back({std::numeric_limits<float>::quiet_NaN(), 0, 0}, {1, 1, 1});
  in.push_back({std::numeric_limits<float>::infinity(), 0, 0}, {1, 1, 1});
  const PackedPointCloud2 packed(in, "r/scanner", 0);
  EXPECT_EQ(unpack_pointcloud2(packed.msg()).size(), 1u);
}

TEST(PointCloud2, InconsistentSizesAreRejected) {
  PointCloud in;
  in.push_back({1, 2, 3}, {1, 1, 1});
  const PackedPointCloud2 packed(in, "r/scanner", 0);
  sensor_msgs_msg_dds__PointCloud2_ m = packed.msg();
  m.width = 1000;  // claims far more points than data holds
  m.row_step = 16000;
  EXPECT_THROW(unpack_pointcloud2(m), PointCloud2Error);
  m = packed.msg();
  m.fields._length = 2;  // no z
  EXPECT_THROW(unpack_pointcloud2(m), PointCloud2Error);
}

TEST(PoseStamped, RoundTripKeepsPoseAndYaw) {
  Pose p;
  p.x = 1.5;
  p.y = -2;
  p.z = 0.25;
  p.yaw = deg2rad(-170);
  OwnedPoseStamped msg;
  to_pose_stamped(p, "robot1/map", 42, msg);
  const Pose q = from_pose_stamped(msg.msg);
  EXPECT_NEAR(q.x, 1.5, 1e-12);
  EXPECT_NEAR(q.yaw, p.yaw, 1e-12);
  EXPECT_NEAR(q.roll, 0, 1e-12);
}

TEST(PoseArray, HoldsEachPoseInOrderWithItsYaw) {
  std::vector<Pose> poses(3);
  for (int i = 0; i < 3; ++i) {
    poses[i].x = i;
    poses[i].y = -i;
    poses[i].z = 0.5 * i;
    poses[i].yaw = deg2rad(90.0 * i);
  }
  OwnedPoseArray msg;
  to_pose_array(poses, "map", 7'000'000'001, msg);
  EXPECT_STREQ(msg.msg.header.frame_id, "map");
  EXPECT_EQ(stamp_ns(msg.msg.header.stamp), 7'000'000'001);
  ASSERT_EQ(msg.msg.poses._length, 3u);
  const auto& third = msg.msg.poses._buffer[2];
  EXPECT_DOUBLE_EQ(third.position.x, 2);
  EXPECT_DOUBLE_EQ(third.position.y, -2);
  EXPECT_DOUBLE_EQ(third.position.z, 1);
  // 180° about z: (x, y, z, w) = (0, 0, 1, 0) up to sign.
  EXPECT_NEAR(std::abs(third.orientation.z), 1, 1e-12);
  EXPECT_NEAR(third.orientation.w, 0, 1e-12);
  EXPECT_FALSE(msg.msg.poses._release) << "the vector owns the poses";

  to_pose_array({}, "map", 1, msg);
  EXPECT_EQ(msg.msg.poses._length, 0u) << "an empty plan is an empty array";
}

}  // namespace
}  // namespace scanplan::dds

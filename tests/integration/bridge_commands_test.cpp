// The simulated robot on DDS, driven the way the server drives it: move commands are checked
// against the true world (refused with a reason when off the map or unreachable), and a scan
// command yields the panorama, its calibration, the pose and the points under one stamp.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>

#include "child_process.hpp"
#include "ros2_types.h"
#include "scanplan.h"
#include "scanplan/io/image_codec.hpp"
#include "scanplan/mapping/colorizer.hpp"
#include "scanplan/msgs/camera_info.hpp"
#include "scanplan/msgs/dds_participant.hpp"
#include "scanplan/msgs/pointcloud2.hpp"
#include "scanplan/msgs/pose_stamped.hpp"
#include "scanplan/msgs/topics.hpp"
#include "test_domain.hpp"

namespace scanplan {
namespace {

using namespace std::chrono_literals;

// Polls `fn` until it returns true or the timeout passes.
bool eventually(const std::function<bool()>& fn, std::chrono::milliseconds timeout = 30s) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (fn()) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

class BridgeCommands : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    setenv(
        "CYCLONEDDS_URI",
        "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface "
        "address=\"127.0.0.1\" multicast=\"true\"/></Interfaces></General></Domain></CycloneDDS>",
        1);
    // The yard with exact reported poses, so positions can be compared to the goals.
    nlohmann::json world;
    std::ifstream(SCANPLAN_SOURCE_DIR "/samples/worlds/yard.json") >> world;
    world["pose_noise"] = {
        {"model", "absolute"}, {"xy_sigma_m", 0}, {"z_sigma_m", 0}, {"yaw_sigma_deg", 0}};
    world["scanner"] = {{"rotation_step_deg", 1.0}, {"camera_width_px", 512}};
    world_file_ =
        new std::filesystem::path(std::filesystem::temp_directory_path() /
                                  ("bridge_commands_" + std::to_string(getpid()) + ".json"));
    std::ofstream(*world_file_) << world.dump();

    // The status topic keeps the last sample only: a drive must last long enough (18 m at 50×:
    // 0.7 s) for the test to see "moving" before "arrived" replaces it, on a loaded machine too.
    bridge_ = new test::ChildProcess(SCANPLAN_BRIDGE,
                                     {"--world", world_file_->string(), "--domain",
                                      std::to_string(test::test_domain()), "--time-scale", "50"});
    participant_ = new dds::Participant(test::test_domain());
    using dds::QosKind;
    auto& p = *participant_;
    move_ = p.writer(scanplan_MoveCommand_desc, topics::kMoveCommand, QosKind::kCommand);
    scan_ = p.writer(scanplan_ScanCommand_desc, topics::kScanCommand, QosKind::kCommand);
    // Keep-all readers: the test wants every state the robot passes through.
    status_ = p.reader(scanplan_RobotStatus_desc, topics::kRobotStatus, QosKind::kCommand);
    points_ = p.reader(sensor_msgs_msg_dds__PointCloud2__desc, topics::kPoints, QosKind::kScanData);
    pose_ = p.reader(geometry_msgs_msg_dds__PoseStamped__desc, topics::kPose, QosKind::kScanData);
    image_ =
        p.reader(sensor_msgs_msg_dds__CompressedImage__desc, topics::kImage, QosKind::kScanData);
    info_ =
        p.reader(sensor_msgs_msg_dds__CameraInfo__desc, topics::kCameraInfo, QosKind::kScanData);
    ASSERT_TRUE(dds::wait_for_reader(move_, 30s)) << "the bridge never subscribed to move commands";
    ASSERT_TRUE(dds::wait_for_reader(scan_, 30s));
  }
  static void TearDownTestSuite() {
    EXPECT_EQ(bridge_->terminate(), 0) << "the bridge stops cleanly on SIGTERM";
    delete bridge_;
    delete participant_;
    std::filesystem::remove(*world_file_);
    delete world_file_;
  }

  struct Status {
    std::uint32_t command_id;
    std::string state, message;
    double x, y, z, yaw_deg;
  };

  // Sends a move and returns the robot's final word on it ("arrived" or "refused").
  Status move_to(double x, double y, double yaw_deg) {
    const std::uint32_t id = next_id_++;
    scanplan_MoveCommand cmd{const_cast<char*>("robot1"), id, x, y, yaw_deg};
    dds::check(dds_write(move_, &cmd), "dds_write");
    Status last{};
    const bool done = eventually([&] {
      bool final_state = false;
      dds::take_all<scanplan_RobotStatus>(status_, [&](const scanplan_RobotStatus& s) {
        if (s.command_id != id) return;
        last = {s.command_id, s.state, s.message, s.x, s.y, s.z, s.yaw_deg};
        seen_states_.push_back(last.state);
        final_state |= last.state == "arrived" || last.state == "refused";
      });
      return final_state;
    });
    EXPECT_TRUE(done) << "no final status for move " << id;
    return last;
  }

  static inline test::ChildProcess* bridge_ = nullptr;
  static inline dds::Participant* participant_ = nullptr;
  static inline std::filesystem::path* world_file_ = nullptr;
  static inline dds_entity_t move_, scan_, status_, points_, pose_, image_, info_;
  static inline std::uint32_t next_id_ = 1;
  std::vector<std::string> seen_states_;
};

TEST_F(BridgeCommands, OffMapGoalIsRefusedWithAReason) {
  const Status s = move_to(100, 100, 0);
  EXPECT_EQ(s.state, "refused");
  EXPECT_NE(s.message.find("outside the target region"), std::string::npos) << s.message;
}

TEST_F(BridgeCommands, GoalInsideABuildingIsRefused) {
  const Status s = move_to(14, 6, 0);  // the yard's 12.5 m building
  EXPECT_EQ(s.state, "refused");
  EXPECT_FALSE(s.message.empty());
}

TEST_F(BridgeCommands, ReachableGoalIsDrivenTo) {
  const Status s = move_to(0, -15, 90);
  ASSERT_EQ(s.state, "arrived") << s.message;
  EXPECT_NE(std::find(seen_states_.begin(), seen_states_.end(), "moving"), seen_states_.end());
  EXPECT_NEAR(s.x, 0, 1e-9);
  EXPECT_NEAR(s.y, -15, 1e-9);
  EXPECT_NEAR(s.z, 0, 0.01);
  EXPECT_NEAR(s.yaw_deg, 90, 1e-9);
}

TEST_F(BridgeCommands, ScanBringsPanoramaCalibrationPoseAndPointsUnderOneStamp) {
  const Status at = move_to(-20, 10, 0);
  ASSERT_EQ(at.state, "arrived") << at.message;
  scanplan_ScanCommand cmd{const_cast<char*>(""), next_id_++};
  dds::check(dds_write(scan_, &cmd), "dds_write");

  std::optional<PointCloud> cloud;
  std::optional<Pose> pose;
  std::optional<PanoramaCamera> camera;
  std::vector<std::uint8_t> jpeg;
  std::set<std::int64_t> stamps;
  ASSERT_TRUE(eventually(
      [&] {
        dds::take_all<sensor_msgs_msg_dds__PointCloud2_>(points_, [&](const auto& m) {
          cloud = dds::unpack_pointcloud2(m);
          stamps.insert(dds::stamp_ns(m.header.stamp));
        });
        dds::take_all<geometry_msgs_msg_dds__PoseStamped_>(pose_, [&](const auto& m) {
          pose = dds::from_pose_stamped(m);
          stamps.insert(dds::stamp_ns(m.header.stamp));
        });
        dds::take_all<sensor_msgs_msg_dds__CameraInfo_>(info_, [&](const auto& m) {
          camera = dds::from_camera_info(m);
          stamps.insert(dds::stamp_ns(m.header.stamp));
        });
        dds::take_all<sensor_msgs_msg_dds__CompressedImage_>(image_, [&](const auto& m) {
          EXPECT_STREQ(m.format, "jpeg");
          jpeg.assign(m.data._buffer, m.data._buffer + m.data._length);
          stamps.insert(dds::stamp_ns(m.header.stamp));
        });
        return cloud && pose && camera && !jpeg.empty();
      },
      60s));
  EXPECT_EQ(stamps.size(), 1u) << "all parts of one scan carry the same stamp";
  EXPECT_NEAR(pose->x, -20, 1e-9);
  EXPECT_NEAR(pose->y, 10, 1e-9);
  EXPECT_FALSE(cloud->has_colors()) << "the laser sees no colour; the server colourises";
  EXPECT_GT(cloud->size(), 50000u);
  EXPECT_EQ(camera->width_px, 512);
  EXPECT_NEAR(camera->center_robot.z(), 1.15, 1e-9);

  const cv::Mat image = decode_image(jpeg);
  const ColorizeStats stats = colorize(*cloud, image, *camera);
  EXPECT_GT(stats.colored, cloud->size() * 95 / 100);
}

}  // namespace
}  // namespace scanplan

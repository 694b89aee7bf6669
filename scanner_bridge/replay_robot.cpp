#include "replay_robot.hpp"

#include <spdlog/spdlog.h>

#include <fstream>
#include <thread>

#include "scanplan/io/image_codec.hpp"

namespace scanplan::bridge {
namespace {

std::vector<std::uint8_t> read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw std::runtime_error(file.string() + ": cannot open the image");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

ReplayRobot::ReplayRobot(ReplayFolder folder, dds::Participant& participant, ReplayOptions options)
    : folder_(std::move(folder)),
      options_(std::move(options)),
      publisher_(participant, options_.robot_id),
      commands_(participant, options_.robot_id) {}

Pose ReplayRobot::current_pose() const {
  // Before the first scan the robot stands where the recording starts; after the last, it stays.
  if (folder_.size() == 0) return {};
  return folder_.entry(std::min(next_, folder_.size() - 1)).pose;
}

void ReplayRobot::run(const std::atomic<bool>& stop) {
  spdlog::info("robot '{}' replaying {} scans from {}", options_.robot_id, folder_.size(),
               folder_.dir().string());
  auto last_status = std::chrono::steady_clock::time_point{};
  while (!stop) {
    if (std::chrono::steady_clock::now() - last_status > std::chrono::seconds(1)) {
      publisher_.status(0, "idle", current_pose());
      last_status = std::chrono::steady_clock::now();
    }
    for (const Command& c : commands_.wait(std::chrono::milliseconds(200))) {
      if (stop) break;
      if (const auto* s = std::get_if<ScanRequest>(&c)) scan(s->command_id, stop);
      if (const auto* m = std::get_if<MoveRequest>(&c)) {
        publisher_.status(m->command_id, "refused", current_pose(),
                          "this robot replays a recording: it scans where the recording says "
                          "and cannot drive to a goal");
      }
    }
  }
  publisher_.goodbye(current_pose());
}

void ReplayRobot::scan(std::uint32_t command_id, const std::atomic<bool>& stop) {
  if (next_ >= folder_.size()) {
    publisher_.progress(
        command_id, "failed", 0.0f,
        "the recording has no more scans (" + std::to_string(folder_.size()) + " played)");
    return;
  }
  const std::size_t index = next_++;
  const ReplayFolder::Entry& entry = folder_.entry(index);
  publisher_.status(command_id, "scanning", entry.pose);
  publisher_.progress(command_id, "scanning", 0.0f);
  const auto started = std::chrono::steady_clock::now();
  std::string failure;
  PointCloud cloud;
  std::optional<CameraShot> shot;
  try {
    cloud = folder_.load(index);
    if (entry.image) {
      // Recorded panoramas are equirectangular with the default camera mount; their size
      // comes from the image itself.
      CameraShot s{read_bytes(*entry.image), PanoramaCamera::for_scanner(ScannerConfig{})};
      const cv::Mat decoded = decode_image(s.jpeg);
      s.camera.width_px = decoded.cols;
      s.camera.height_px = decoded.rows;
      shot = std::move(s);
    }
  } catch (const std::exception& e) {
    failure = e.what();
  }
  // A recorded scan still takes its minute, so the operator sees the session as it happened.
  if (options_.time_scale > 0) {
    const auto until =
        started +
        std::chrono::duration_cast<std::chrono::steady_clock::duration>(
            std::chrono::duration<double>(options_.scan_duration_s / options_.time_scale));
    while (!stop && std::chrono::steady_clock::now() < until) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  if (stop) return;
  if (!failure.empty()) {
    spdlog::error("scan {} of the recording is broken: {}", index + 1, failure);
    publisher_.progress(command_id, "failed", 1.0f, failure);
    publisher_.status(command_id, "idle", entry.pose, failure);
    return;
  }
  publisher_.scan(cloud, entry.pose, shot);
  publisher_.progress(command_id, "done", 1.0f, std::to_string(cloud.size()) + " points");
  publisher_.status(command_id, "idle", entry.pose);
  spdlog::info("scan command {}: replayed {} ({} points)", command_id,
               entry.scan.filename().string(), cloud.size());
}

}  // namespace scanplan::bridge

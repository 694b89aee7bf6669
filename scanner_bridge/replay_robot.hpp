#pragma once

#include <atomic>
#include <cstdint>

#include "command_reader.hpp"
#include "scanner_publisher.hpp"
#include "scanplan/io/replay_folder.hpp"

namespace scanplan::bridge {

struct ReplayOptions {
  std::string robot_id = "robot1";
  double time_scale = 1.0;
  double scan_duration_s = 60.0;  // simulated time a recorded scan takes to "arrive"
};

// Plays a folder of recorded scans (ReplayFolder), one per scan command, in order. The robot
// cannot drive: where it scans next is what the recording says, so move commands are refused.
// A broken scan file is reported on the progress topic and skipped; the bridge keeps serving.
class ReplayRobot {
 public:
  ReplayRobot(ReplayFolder folder, dds::Participant& participant, ReplayOptions options);
  void run(const std::atomic<bool>& stop);

 private:
  void scan(std::uint32_t command_id, const std::atomic<bool>& stop);
  Pose current_pose() const;

  ReplayFolder folder_;
  ReplayOptions options_;
  ScannerPublisher publisher_;
  CommandReader commands_;
  std::size_t next_ = 0;
};

}  // namespace scanplan::bridge

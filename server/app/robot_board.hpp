#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

#include "app/states.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan::server {

// What the session knows of one robot's current scan.
struct RobotScanState {
  std::uint32_t command_id = 0;
  ScanState state = ScanState::kIdle;
  float fraction = 0;
  std::string message;
};

// What the robot last said about itself (scanplan_RobotStatus).
struct RobotStatus {
  std::uint32_t command_id = 0;
  RobotActivity state = RobotActivity::kUnknown;
  std::string message;
  Pose reported;
};

// Whether the robot's bridge is alive on DDS (its liveliness lease, docs/dds.md).
struct RobotConnection {
  bool connected = true;
  std::string lost_at;  // UTC, ISO 8601; empty while connected
  std::string reason;   // why it was lost; empty while connected
};

struct RobotState {
  RobotStatus status;
  RobotScanState scan;
  RobotConnection connection;
};

// The robots as the operator sees them: written by the DDS thread, read by the API. Thread-safe.
class RobotBoard {
 public:
  void set_scan_state(const std::string& robot, RobotScanState state);
  void set_status(const std::string& robot, RobotStatus status);
  void set_connection(const std::string& robot, RobotConnection connection);
  std::map<std::string, RobotState> states() const;
  // Where `robot` last said it is; nothing for a robot never heard of.
  std::optional<Pose> reported_pose(const std::string& robot) const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, RobotState> robots_;
};

}  // namespace scanplan::server

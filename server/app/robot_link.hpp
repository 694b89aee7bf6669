#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>

#include "scanplan/geometry/pose.hpp"
#include "storage/session_store.hpp"

namespace scanplan::server {

// No robot can take the command: no bridge listens, or that robot's bridge is lost.
class NoScannerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// What a bridge's loss cost: the scan it was taking (or whose parts were still arriving).
struct ScanLoss {
  std::uint32_t command_id = 0;  // 0 when only parts of an unrequested scan were in
  float fraction = 0;            // how far the scanner had got
  std::size_t parts_discarded = 0;
};

struct RobotLoss {
  std::string robot;
  std::string reason;   // why the server counts the bridge as gone
  std::string lost_at;  // UTC, ISO 8601
  std::optional<ScanLoss> scan;
};

// The reason a scan lost with its bridge is reported with.
inline constexpr const char* kScanLostReason = "bridge lost during the scan";

// What the mission asks of the robots: the server's DDS link, or a fake in tests. The commands
// return their command id and throw NoScannerError when no robot can take them.
class RobotLink {
 public:
  virtual ~RobotLink() = default;
  // Asks `robot` (empty: every robot) for one scan.
  virtual std::uint32_t request_scan(const std::string& robot) = 0;
  // Sends `robot` to (x, y) facing yaw (map frame).
  virtual std::uint32_t request_move(const std::string& robot, double x, double y,
                                     double yaw_deg) = 0;
  // Announces where the operator sent `robot`; logs rather than throws.
  virtual void publish_goal(const std::string& robot, const Pose& goal) = 0;
};

// Where the operator's annotations go besides the session and the browsers (DDS, latched).
class AnnotationPublisher {
 public:
  virtual ~AnnotationPublisher() = default;
  virtual void publish_annotation(const Annotation& annotation) = 0;
  // Disposes a deleted annotation, so late joiners no longer get it.
  virtual void withdraw_annotation(std::int64_t id) = 0;
};

}  // namespace scanplan::server

#pragma once

#include <optional>
#include <string>

// Topic names (DESIGN.md "DDS"): ROS-typed topics carry the ROS 2 `rt/` prefix so that a
// ROS 2 node on rmw_cyclonedds sees them as /scanner/points etc.
namespace scanplan::topics {

inline constexpr const char* kPoints = "rt/scanner/points";
inline constexpr const char* kPose = "rt/scanner/pose";
inline constexpr const char* kImage = "rt/scanner/image/compressed";
inline constexpr const char* kCameraInfo = "rt/scanner/camera_info";
inline constexpr const char* kRobotStatus = "scanplan_RobotStatus";
inline constexpr const char* kMoveCommand = "scanplan_MoveCommand";
inline constexpr const char* kScanProgress = "scanplan_ScanProgress";
inline constexpr const char* kScanCommand = "scanplan_ScanCommand";
// Server → anyone (a ROS 2 node sees the first three as /scanplan/map, /scanplan/candidates and
// /scanplan/goal).
inline constexpr const char* kMap = "rt/scanplan/map";
inline constexpr const char* kCandidates = "rt/scanplan/candidates";
inline constexpr const char* kGoal = "rt/scanplan/goal";
inline constexpr const char* kAnnotation = "scanplan_Annotation";
// Several robots: each robot's own plan and goal also go out under its namespace, as ROS 2
// namespaces a robot's topics (/robot2/scanplan/candidates): "rt/<robot>/scanplan/candidates".
inline constexpr const char* kRobotCandidatesSuffix = "/scanplan/candidates";
inline constexpr const char* kRobotGoalSuffix = "/scanplan/goal";

// "rt/<robot><suffix>", or nothing when the robot id cannot be a ROS 2 namespace (a letter,
// then letters, digits and underscores).
inline std::optional<std::string> robot_topic(const std::string& robot, const char* suffix) {
  const auto alpha = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  if (robot.empty() || !alpha(robot[0])) return std::nullopt;
  for (const char c : robot) {
    if (!alpha(c) && !(c >= '0' && c <= '9') && c != '_') return std::nullopt;
  }
  return "rt/" + robot + suffix;
}
// header.frame_id of what the server publishes in the map frame. Plain "map", the frame name ROS
// tools (rviz, nav2) expect, since these topics are about the shared map rather than one robot.
inline constexpr const char* kMapFrame = "map";

}  // namespace scanplan::topics

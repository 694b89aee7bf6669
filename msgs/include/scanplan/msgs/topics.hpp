#pragma once

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

}  // namespace scanplan::topics

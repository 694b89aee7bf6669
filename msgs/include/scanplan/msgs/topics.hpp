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
// Server → anyone (a ROS 2 node sees the first three as /scanplan/map, /scanplan/candidates and
// /scanplan/goal).
inline constexpr const char* kMap = "rt/scanplan/map";
inline constexpr const char* kCandidates = "rt/scanplan/candidates";
inline constexpr const char* kGoal = "rt/scanplan/goal";
inline constexpr const char* kAnnotation = "scanplan_Annotation";
// header.frame_id of what the server publishes in the map frame. Plain "map", the frame name ROS
// tools (rviz, nav2) expect, since these topics are about the shared map rather than one robot.
inline constexpr const char* kMapFrame = "map";

}  // namespace scanplan::topics

#include "app/robot_board.hpp"

namespace scanplan::server {

void RobotBoard::set_scan_state(const std::string& robot, RobotScanState state) {
  std::lock_guard lock(mutex_);
  robots_[robot].scan = std::move(state);
}

void RobotBoard::set_status(const std::string& robot, RobotStatus status) {
  std::lock_guard lock(mutex_);
  robots_[robot].status = std::move(status);
}

void RobotBoard::set_connection(const std::string& robot, RobotConnection connection) {
  std::lock_guard lock(mutex_);
  robots_[robot].connection = std::move(connection);
}

std::map<std::string, RobotState> RobotBoard::states() const {
  std::lock_guard lock(mutex_);
  return robots_;
}

std::optional<Pose> RobotBoard::reported_pose(const std::string& robot) const {
  std::lock_guard lock(mutex_);
  const auto it = robots_.find(robot);
  if (it == robots_.end()) return std::nullopt;
  return it->second.status.reported;
}

}  // namespace scanplan::server

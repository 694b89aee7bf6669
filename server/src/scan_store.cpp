#include "scan_store.hpp"

#include "scanplan/core/draco_codec.hpp"

namespace scanplan::server {

ScanRecord ScanStore::add(const std::string& robot_id, const Pose& pose, std::int64_t stamp_ns,
                          const PointCloud& cloud) {
  const Eigen::Affine3f map_from_robot = pose.isometry().cast<float>();
  PointCloud placed;
  placed.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    placed.push_back(map_from_robot * cloud.points[i],
                     cloud.has_colors() ? cloud.colors[i] : Rgb{128, 128, 128});
  }

  // Writers take turns on encode_mutex_; readers only wait for the short commit below, and
  // they see the scan, its points and the map encoding that includes it appear together.
  std::lock_guard encode_lock(encode_mutex_);
  PointCloud next;
  ScanRecord record;
  {
    std::lock_guard lock(mutex_);
    next = map_;
    record.id = scans_.size() + 1;
  }
  next.append(placed);
  record.robot_id = robot_id;
  record.pose = pose;
  record.stamp_ns = stamp_ns;
  record.points = placed.size();
  std::shared_ptr<const std::string> encoded;
  if (!next.empty()) encoded = std::make_shared<const std::string>(encode_draco(next));
  std::lock_guard lock(mutex_);
  scans_.push_back(record);
  map_ = std::move(next);
  encoded_ = std::move(encoded);
  return record;
}

std::vector<ScanRecord> ScanStore::scans() const {
  std::lock_guard lock(mutex_);
  return scans_;
}

std::size_t ScanStore::scan_count() const {
  std::lock_guard lock(mutex_);
  return scans_.size();
}

std::size_t ScanStore::point_count() const {
  std::lock_guard lock(mutex_);
  return map_.size();
}

Bounds3 ScanStore::bounds() const {
  std::lock_guard lock(mutex_);
  return bounds_of(map_);
}

std::shared_ptr<const std::string> ScanStore::encoded_map() const {
  std::lock_guard lock(mutex_);
  return encoded_;
}

void ScanStore::set_scan_state(const std::string& robot_id, RobotScanState state) {
  std::lock_guard lock(mutex_);
  robots_[robot_id].scan = std::move(state);
}

void ScanStore::set_robot_status(const std::string& robot_id, RobotStatus status) {
  std::lock_guard lock(mutex_);
  robots_[robot_id].status = std::move(status);
}

std::map<std::string, RobotState> ScanStore::robot_states() const {
  std::lock_guard lock(mutex_);
  return robots_;
}

}  // namespace scanplan::server

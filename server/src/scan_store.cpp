#include "scan_store.hpp"

#include "scanplan/core/draco_codec.hpp"
#include "scanplan/core/top_view.hpp"

namespace scanplan::server {

ScanStore::ScanStore(PipelineConfig pipeline) : pipeline_(pipeline) {}

const std::vector<std::string>& ScanStore::layer_names() {
  static const std::vector<std::string> kNames = {"regions", "elevation", "movable"};
  return kNames;
}

void ScanStore::add(const StoredScan& scan, const PointCloud& cloud) {
  const Pose& pose = scan.placed;
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
  {
    std::lock_guard lock(mutex_);
    next = map_;
  }
  next.append(placed);
  std::shared_ptr<const std::string> encoded;
  if (!next.empty()) encoded = std::make_shared<const std::string>(encode_draco(next));

  pipeline_.add_scan(cloud, pose);
  std::map<std::string, std::shared_ptr<const std::vector<std::uint8_t>>> layers;
  MapAreas areas;
  if (pipeline_.regions() && pipeline_.movable()) {
    const RegionMap& regions = *pipeline_.regions();
    const MovableRegion& movable = *pipeline_.movable();
    const auto png = [](const cv::Mat& img) {
      return std::make_shared<const std::vector<std::uint8_t>>(encode_png(img));
    };
    layers["regions"] = png(render_regions(regions, &movable, pipeline_.scan_points()));
    layers["elevation"] = png(render_elevation(pipeline_.map(), regions));
    layers["movable"] = png(render_movable(pipeline_.map(), movable, regions));
    areas = {regions.completed_m2(), regions.low_resolution_m2(), regions.unscanned_m2(),
             movable.area_m2()};
  }

  std::lock_guard lock(mutex_);
  scans_.push_back(scan);
  map_ = std::move(next);
  encoded_ = std::move(encoded);
  layers_ = std::move(layers);
  areas_ = areas;
}

std::vector<StoredScan> ScanStore::scans() const {
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

std::shared_ptr<const std::vector<std::uint8_t>> ScanStore::layer_png(const std::string& name) const {
  std::lock_guard lock(mutex_);
  const auto it = layers_.find(name);
  return it == layers_.end() ? nullptr : it->second;
}

MapAreas ScanStore::areas() const {
  std::lock_guard lock(mutex_);
  return areas_;
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

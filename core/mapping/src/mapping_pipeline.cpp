#include "scanplan/mapping/mapping_pipeline.hpp"

namespace scanplan {

MappingPipeline::MappingPipeline(PipelineConfig config) : config_(config), map_(config.mls) {}

InsertStats MappingPipeline::add_placed_scan(const PointCloud& in_map, const Pose& placed_at,
                                             const Pose& pose) {
  const InsertStats stats =
      map_.insert_placed_scan(in_map, placed_at.isometry(), pose.isometry(), sensor());
  joined(pose);
  return stats;
}

void MappingPipeline::replace_scans(const std::vector<PlacedScan>& scans,
                                    const std::vector<Bounds3>& changed) {
  MlsMap::Tiles tiles = map_.tiles();
  for (const Bounds3& box : changed) tiles.add(box);
  poses_.clear();
  for (const PlacedScan& s : scans) poses_.push_back(s.pose);
  if (!tiles.empty()) {
    map_.clear(tiles);
    // West and east of the changed tiles at once, each in a map of its own (a cell's state
    // follows from the points that reached it, in their order, whoever inserts them).
    const auto [west, east] = tiles.halves();
    const MlsMap::Tiles* part_tiles[2] = {&west, &east};
    MlsMap parts[2] = {MlsMap(config_.mls), MlsMap(config_.mls)};
#pragma omp parallel for num_threads(config_.threads > 0 ? config_.threads : 2) schedule(static, 1)
    for (int k = 0; k < 2; ++k) {
      for (const PlacedScan& s : scans) {
        if (part_tiles[k]->reaches(s.bounds)) {
          parts[k].insert_placed_scan(*s.in_map, s.placed_at.isometry(), s.pose.isometry(),
                                      sensor(), part_tiles[k]);
        }
      }
    }
    for (MlsMap& part : parts) map_.adopt(std::move(part));
  }
  if (poses_.empty()) {
    regions_.reset();
    movable_.reset();
  }
  update_regions();
}

Eigen::Vector3d MappingPipeline::sensor() const {
  return {0, 0, config_.sensor_height_m};
}

void MappingPipeline::joined(const Pose& pose) {
  poses_.push_back(pose);
  if (!target_) {
    const Eigen::Vector2d half = Eigen::Vector2d::Constant(config_.default_target_side_m / 2);
    const Eigen::Vector2d c(pose.x, pose.y);
    target_ = TargetRegion::rectangle(c - half, c + half);
  }
  update_regions();
}

void MappingPipeline::set_target(TargetRegion target) {
  target_ = std::move(target);
  update_regions();
}

void MappingPipeline::set_region_configs(const RegionConfig& regions,
                                         const MovableConfig& movable) {
  config_.regions = regions;
  config_.movable = movable;
  update_regions();
}

std::vector<Eigen::Vector2d> MappingPipeline::scan_points() const {
  std::vector<Eigen::Vector2d> out;
  out.reserve(poses_.size());
  for (const Pose& p : poses_) out.emplace_back(p.x, p.y);
  return out;
}

void MappingPipeline::update_regions() {
  if (poses_.empty() || !target_) return;
  regions_ = segment_regions(map_, *target_, scan_points(), config_.regions);
  // The robot stands where it scanned last; its floor is the pose's height.
  const Pose& robot = poses_.back();
  movable_ = movable_region(map_, {robot.x, robot.y, robot.z}, config_.movable);
}

}  // namespace scanplan

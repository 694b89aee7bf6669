#include "scanplan/mission/mission_pipeline.hpp"

#include <utility>

namespace scanplan {
namespace {

// The pipeline's region thresholds are the planner's: one set, changed by the operator.
PipelineConfig with_planner_thresholds(PipelineConfig mapping, const PlannerConfig& planner) {
  mapping.regions = planner.regions;
  mapping.movable = planner.movable;
  return mapping;
}

}  // namespace

MissionPipeline::MissionPipeline(MissionConfig config)
    : config_(std::move(config)),
      mapping_(with_planner_thresholds(config_.mapping, config_.planner)),
      sensor_frame_(config_.pose_noise) {
  if (config_.matching) anchored_map_.emplace(config_.mapping.mls);
}

bool MissionPipeline::has_map() const {
  return mapping_.regions() && mapping_.movable() && mapping_.target();
}

std::optional<MissionPipeline::MatchInput> MissionPipeline::match_input(
    const Pose& reported) const {
  if (!config_.matching || placed_.empty()) return std::nullopt;
  const Pose start = prior(reported);
  return MatchInput{
      points_near(start.x, start.y, config_.matching->target_radius_m, /*anchored_only=*/true),
      *config_.matching, start};
}

std::optional<MapMatch> MissionPipeline::place(const PointCloud& scan, const Pose& reported) const {
  const std::optional<MatchInput> in = match_input(reported);
  if (!in) return std::nullopt;
  return match_to_map(in->map_points, scan, in->prior, in->config);
}

std::shared_ptr<const PointCloud> MissionPipeline::to_map_frame(const PointCloud& scan,
                                                                const Pose& placed) {
  const Eigen::Affine3f map_from_scan = placed.isometry().cast<float>();
  PointCloud in_map;
  in_map.reserve(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    in_map.push_back(map_from_scan * scan.points[i],
                     scan.has_colors() ? scan.colors[i] : Rgb{128, 128, 128});
  }
  return std::make_shared<const PointCloud>(std::move(in_map));
}

std::shared_ptr<const PointCloud> MissionPipeline::add(const PointCloud& scan,
                                                       const Placement& where) {
  add(scan, where, to_map_frame(scan, where.placed));
  return placed_.back();
}

void MissionPipeline::add(const PointCloud& scan, const Placement& where,
                          std::shared_ptr<const PointCloud> in_map) {
  mapping_.add_scan(scan, where.placed);
  const bool anchored = placed_.empty() || where.matched;
  anchored_.push_back(anchored ? 1 : 0);
  if (anchored) {
    sensor_frame_.add(where.reported, where.placed);
    if (anchored_map_) {
      anchored_map_->insert_scan(scan, where.placed.isometry(),
                                 Eigen::Vector3d(0, 0, config_.mapping.sensor_height_m));
    }
  }
  placed_.push_back(std::move(in_map));
}

std::vector<FleetPlan> MissionPipeline::plan(const std::vector<FleetRobot>& robots,
                                             std::vector<Eigen::Vector3d> claimed) const {
  if (!has_map()) return {};
  return plan_fleet(mapping_.map(), *mapping_.target(), mapping_.scan_points(), robots,
                    std::move(claimed), config_.planner, anchored_map());
}

Plan MissionPipeline::plan_from(const Eigen::Vector3d& robot, std::uint64_t seed) const {
  if (!has_map()) return {};
  PlannerConfig planner = config_.planner;
  planner.seed = seed;
  const std::vector<Eigen::Vector2d> points = mapping_.scan_points();
  PlanInput in{mapping_.map(), *mapping_.target(), points, robot};
  in.anchored = anchored_map();
  return plan_next_scan(in, planner);
}

void MissionPipeline::set_planner(const PlannerConfig& planner) {
  config_.planner = planner;
  mapping_.set_region_configs(planner.regions, planner.movable);
}

void MissionPipeline::set_target(TargetRegion target) {
  mapping_.set_target(std::move(target));
}

PointCloud MissionPipeline::points_near(double x, double y, double radius_m,
                                        bool anchored_only) const {
  PointCloud out;
  const Eigen::Vector2f c(static_cast<float>(x), static_cast<float>(y));
  const float r2 = static_cast<float>(radius_m * radius_m);
  for (std::size_t i = 0; i < placed_.size(); ++i) {
    if (anchored_only && !anchored_[i]) continue;
    for (const auto& p : placed_[i]->points) {
      if ((p.head<2>() - c).squaredNorm() <= r2) out.points.push_back(p);
    }
  }
  return out;
}

}  // namespace scanplan

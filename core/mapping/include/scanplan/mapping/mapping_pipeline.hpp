#pragma once

#include <optional>
#include <vector>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/target_region.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"

namespace scanplan {

struct PipelineConfig {
  MlsConfig mls;
  MovableConfig movable;
  RegionConfig regions;
  double sensor_height_m = 1.0;  // the laser's centre above the scan frame's origin
  // Until the operator draws a target region, the one used is a square of this side centred
  // on the first scan point (the paper's campus is about 200 m across, §3.5).
  double default_target_side_m = 200.0;
  // Scans re-placed (replace_scans) go into the west and east halves of the tiles they change
  // on this many threads (0: two, one a half): on a 200-scan campus session the map stage after
  // a correction took 0.4–1.5 s on one.
  int threads = 0;
};

// The mapping half of the paper's loop (§3, steps 1–3): each scan goes into the MLS map at its
// (corrected) pose, then the movable region and the C/M/U segmentation are brought up to date.
// Pure computation: the server serialises access to it.
class MappingPipeline {
 public:
  explicit MappingPipeline(PipelineConfig config = {});

  // A scan in measuring order, its points in the map frame as placed at `placed_at` (a scan in
  // its own frame, origin on the ground under the scanner: `placed_at` the origin); the map holds
  // it at `pose`.
  InsertStats add_placed_scan(const PointCloud& in_map, const Pose& placed_at, const Pose& pose);

  struct PlacedScan {
    const PointCloud* in_map = nullptr;  // its points in the map frame, placed at `placed_at`
    Pose placed_at;
    Pose pose;       // where the map holds the scan (its points moved there from placed_at)
    Bounds3 bounds;  // of its points as the map holds them
  };
  // The map's scans after some moved, left, or joined late: `scans` (in the order the map took
  // them) are all it holds now. Only the tiles reaching `changed` (where the scans that moved or
  // left lay, where the moved and the late ones lie now) are made anew, from the scans reaching
  // them; elsewhere the map stands as the same scans built it. The regions and the movable
  // region follow once, not once a scan: rebuilding a long session's map scan by scan, each
  // step segmenting the whole map, held the operator up for seconds.
  void replace_scans(const std::vector<PlacedScan>& scans, const std::vector<Bounds3>& changed);
  void set_target(TargetRegion target);
  // New thresholds for segmentation (completed radius) and the movable region (step height).
  void set_region_configs(const RegionConfig& regions, const MovableConfig& movable);

  const MlsMap& map() const { return map_; }
  const std::vector<Pose>& scan_poses() const { return poses_; }
  std::vector<Eigen::Vector2d> scan_points() const;
  // Nothing before the first scan (and no target region set).
  const std::optional<TargetRegion>& target() const { return target_; }
  const std::optional<RegionMap>& regions() const { return regions_; }
  const std::optional<MovableRegion>& movable() const { return movable_; }
  const PipelineConfig& config() const { return config_; }

 private:
  Eigen::Vector3d sensor() const;  // the laser's centre in a scan's own frame
  void joined(const Pose& pose);
  void update_regions();

  PipelineConfig config_;
  MlsMap map_;
  std::vector<Pose> poses_;
  std::optional<TargetRegion> target_;
  std::optional<RegionMap> regions_;
  std::optional<MovableRegion> movable_;
};

}  // namespace scanplan

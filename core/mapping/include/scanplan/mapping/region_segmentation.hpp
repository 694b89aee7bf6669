#pragma once

#include <Eigen/Core>
#include <vector>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/geometry/target_region.hpp"
#include "scanplan/mapping/mls_map.hpp"

namespace scanplan {

// Paper §3.3: scan-completed (C), low-resolution (M) and unscanned (U) cells of the target region.
enum class Region : std::uint8_t {
  kOutside = 0,    // not in the target region
  kUnscanned,      // U: no data (too far, or occluded)
  kLowResolution,  // M: data, but farther than completed_radius_m from every scan point
  kCompleted,      // C: data within completed_radius_m of some scan point
};

struct RegionConfig {
  double completed_radius_m = 20.0;  // paper §3.3: 20 m
};

struct RegionMap {
  CellGrid<Region> cells;  // covers the target region's bounding box
  std::size_t completed = 0, low_resolution = 0, unscanned = 0;
  double cell_area_m2() const { return cells.cell_m * cells.cell_m; }
  double completed_m2() const { return static_cast<double>(completed) * cell_area_m2(); }
  double low_resolution_m2() const { return static_cast<double>(low_resolution) * cell_area_m2(); }
  double unscanned_m2() const { return static_cast<double>(unscanned) * cell_area_m2(); }
  // C ∪ M: the paper's "detection area" (§3.5).
  double detected_m2() const { return completed_m2() + low_resolution_m2(); }
  Region at(CellIndex c) const {
    const auto o = cells.offset(c);
    return o ? cells.values[*o] : Region::kOutside;
  }
};

// A cell belongs to the target region when its centre does.
RegionMap segment_regions(const MlsMap& map, const TargetRegion& target,
                          const std::vector<Eigen::Vector2d>& scan_points,
                          const RegionConfig& config = {});

}  // namespace scanplan

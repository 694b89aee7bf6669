#pragma once

#include <Eigen/Core>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/mapping/mls_map.hpp"

namespace scanplan {

struct MovableConfig {
  // Largest height difference between neighbouring cells the robot drives over (paper §3.2:
  // 0.15 m).
  double max_step_m = 0.15;
  // Free height the robot needs above a surface (must not exceed the map's robot_height_m,
  // below which patches are merged and their gaps no longer seen).
  double clearance_m = 1.5;
  // A patch deeper than this is a wall or an obstacle's side, not a floor. It must exceed
  // max_step_m plus the range noise, or slopes the robot can climb would read as walls.
  double max_patch_extent_m = 0.3;
  // kDem keeps only the highest surface of each cell, as a Digital Elevation Map does: for
  // comparison (paper §3.1, Fig. 2), where the ground under a canopy disappears.
  enum class Surfaces { kMls, kDem } surfaces = Surfaces::kMls;
};

// The movable region (paper §3.2): cells whose floor patch is connected to the robot's current
// position through neighbouring floors differing in height by less than max_step_m, with
// clearance above. Per cell it holds the floor's patch index in its cell, or -1.
struct MovableRegion {
  CellGrid<std::int8_t> patch;
  std::size_t cells = 0;
  double area_m2() const { return static_cast<double>(cells) * patch.cell_m * patch.cell_m; }
  bool contains(CellIndex c) const {
    const auto o = patch.offset(c);
    return o && patch.values[*o] >= 0;
  }
};

// Flood fill over the map from the floor under `robot` (x, y, and the height of the ground the
// robot stands on). An empty region when there is no floor within a cell of it.
MovableRegion movable_region(const MlsMap& map, const Eigen::Vector3d& robot,
                             const MovableConfig& config = {});

// Whether a patch can carry the robot: thin enough and with headroom up to the next patch.
bool is_floor(const MlsCell& cell, int patch, const MovableConfig& config);

}  // namespace scanplan

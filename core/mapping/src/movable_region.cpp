#include "scanplan/mapping/movable_region.hpp"

#include <cmath>
#include <deque>
#include <limits>

namespace scanplan {

bool is_floor(const MlsCell& cell, int k, const MovableConfig& config) {
  if (config.surfaces == MovableConfig::Surfaces::kDem) {
    // A DEM cell is one column from its lowest to its highest point: only its top is a
    // surface, and the cell is flat only when nothing stands in it.
    return k + 1 == cell.size &&
           cell.dem_height() - cell.patches[0].min_z <= config.max_patch_extent_m;
  }
  const SurfacePatch& p = cell.patches[k];
  if (p.extent() > config.max_patch_extent_m) return false;
  return k + 1 >= cell.size || cell.patches[k + 1].min_z - p.max_z >= config.clearance_m;
}

MovableRegion movable_region(const MlsMap& map, const Eigen::Vector3d& robot,
                             const MovableConfig& config) {
  MovableRegion region;
  const auto extent = map.extent();
  if (!extent) return region;
  const auto [lo, hi] = *extent;
  region.patch = CellGrid<std::int8_t>(lo, hi.x - lo.x + 1, hi.y - lo.y + 1, map.cell_m(), -1);
  auto& grid = region.patch;

  // The floor in `c` whose top is within max_step of `z`, nearest first; -1 if none.
  const auto floor_near = [&](CellIndex c, float z, float tolerance) {
    const MlsCell* cell = map.cell(c);
    if (!cell) return -1;
    int best = -1;
    float best_d = tolerance;
    for (int k = 0; k < cell->size; ++k) {
      const float d = std::abs(cell->patches[k].max_z - z);
      if (d < best_d && is_floor(*cell, k, config)) {
        best = k;
        best_d = d;
      }
    }
    return best;
  };

  // The robot stands on a floor in its own cell, or (when its own cell was not seen well
  // enough) in a neighbouring one.
  const CellIndex start = map.index_of(robot.x(), robot.y());
  std::deque<CellIndex> open;
  for (int r = 0; r <= 1 && open.empty(); ++r) {
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const CellIndex c{start.x + dx, start.y + dy};
        const auto o = grid.offset(c);
        // Half a metre of tolerance: the robot's height comes from its own pose estimate.
        const int k = o ? floor_near(c, static_cast<float>(robot.z()), 0.5f) : -1;
        if (k >= 0 && grid.values[*o] < 0) {
          grid.values[*o] = static_cast<std::int8_t>(k);
          open.push_back(c);
        }
      }
    }
  }

  const float step = static_cast<float>(config.max_step_m);
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  while (!open.empty()) {
    const CellIndex c = open.front();
    open.pop_front();
    ++region.cells;
    const float z = map.cell(c)->patches[grid.values[*grid.offset(c)]].max_z;
    for (int n = 0; n < 8; ++n) {
      const CellIndex next{c.x + kDx[n], c.y + kDy[n]};
      const auto o = grid.offset(next);
      if (!o || grid.values[*o] >= 0) continue;
      const int k = floor_near(next, z, step);
      if (k < 0) continue;
      grid.values[*o] = static_cast<std::int8_t>(k);
      open.push_back(next);
    }
  }
  return region;
}

}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scanplan/geometry/cell_grid.hpp"
#include "scanplan/geometry/target_region.hpp"
#include "scanplan/mapping/mls_map.hpp"
#include "scanplan/mapping/movable_region.hpp"

namespace scanplan {

// Shortest drives from the robot over the movable region (paper §5 future work: "the moving
// cost of mobile robots"): Dijkstra over its cells, 8-connected, a cell_m step straight and
// √2·cell_m diagonally, between floors differing by less than max_step_m (the rule the movable
// region was flooded with, checked again because two movable neighbours may have been reached
// by different routes on either side of a step).
struct TravelMap {
  CellGrid<float> distance_m;     // the movable region's geometry; +inf where not reachable
  CellGrid<std::int32_t> parent;  // offset of the previous cell on the way; -1 at the start
  CellIndex start;
  bool reachable(CellIndex c) const;
  double distance(CellIndex c) const;  // +inf where not reachable
  // Cell centres from the start to `c` (both included); empty where not reachable.
  std::vector<Eigen::Vector2d> path_to(CellIndex c) const;
};

// From the movable cell under `robot` (x, y, floor z), or the nearest movable neighbour when the
// robot's own cell is not movable. With `within`, only cells whose centre is inside it are
// driven through (the start excepted) when the start is inside it; from a start outside it
// every cell is, so that the robot can get in. None whose centre lies in one of `avoid` (the
// operator's no-go zones) is. All distances are +inf when there is no start cell.
TravelMap travel_map(const MlsMap& map, const MovableRegion& movable, const Eigen::Vector3d& robot,
                     const MovableConfig& config, const TargetRegion* within = nullptr,
                     const std::vector<TargetRegion>& avoid = {});

}  // namespace scanplan

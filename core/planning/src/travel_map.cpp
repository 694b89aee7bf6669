#include "scanplan/planning/travel_map.hpp"

#include <cmath>
#include <functional>
#include <limits>
#include <queue>

namespace scanplan {

bool TravelMap::reachable(CellIndex c) const {
  return std::isfinite(distance(c));
}

double TravelMap::distance(CellIndex c) const {
  const auto o = distance_m.offset(c);
  return o ? distance_m.values[*o] : std::numeric_limits<double>::infinity();
}

std::vector<Eigen::Vector2d> TravelMap::path_to(CellIndex c) const {
  std::vector<Eigen::Vector2d> path;
  if (!reachable(c)) return path;
  const double s = distance_m.cell_m;
  for (std::int64_t o = static_cast<std::int64_t>(*distance_m.offset(c)); o >= 0;
       o = parent.values[static_cast<std::size_t>(o)]) {
    const CellIndex at = distance_m.index_at(static_cast<std::size_t>(o));
    path.emplace_back((at.x + 0.5) * s, (at.y + 0.5) * s);
  }
  return {path.rbegin(), path.rend()};
}

TravelMap travel_map(const MlsMap& map, const MovableRegion& movable, const Eigen::Vector3d& robot,
                     const MovableConfig& config, const TargetRegion* within,
                     const std::vector<TargetRegion>& avoid) {
  const auto& grid = movable.patch;
  const float inf = std::numeric_limits<float>::infinity();
  TravelMap t;
  t.distance_m = CellGrid<float>(grid.origin, grid.cols, grid.rows, grid.cell_m, inf);
  t.parent = CellGrid<std::int32_t>(grid.origin, grid.cols, grid.rows, grid.cell_m, -1);
  if (grid.values.empty()) return t;

  // The start as movable_region chose it: the robot's cell, else the neighbour whose floor is
  // nearest the robot's height.
  const CellIndex rc = map.index_of(robot.x(), robot.y());
  std::int64_t start = -1;
  float best = inf;
  for (int r = 0; r <= 1 && start < 0; ++r) {
    for (int dy = -r; dy <= r; ++dy) {
      for (int dx = -r; dx <= r; ++dx) {
        const CellIndex c{rc.x + dx, rc.y + dy};
        const auto o = grid.offset(c);
        if (!o || grid.values[*o] < 0) continue;
        const float d =
            std::abs(map.cell(c)->patches[grid.values[*o]].max_z - static_cast<float>(robot.z()));
        if (d < best) {
          best = d;
          start = static_cast<std::int64_t>(*o);
        }
      }
    }
  }
  if (start < 0) return t;
  t.start = grid.index_at(static_cast<std::size_t>(start));

  // A robot standing outside the target region (it was driven there by hand, or the operator
  // drew the region elsewhere) may drive anywhere to get into it; one inside keeps to it.
  const Eigen::Vector2d start_centre = map.center_of(t.start);
  const TargetRegion* keep_in =
      within && within->contains(start_centre.x(), start_centre.y()) ? within : nullptr;
  // The floor height per movable cell; NaN marks cells not to be driven on.
  std::vector<float> floor(grid.values.size(), std::nanf(""));
  for (std::size_t o = 0; o < grid.values.size(); ++o) {
    if (grid.values[o] < 0) continue;
    const CellIndex c = grid.index_at(o);
    const Eigen::Vector2d centre = map.center_of(c);
    if (keep_in && !keep_in->contains(centre.x(), centre.y())) continue;
    if (in_any(avoid, centre)) continue;
    floor[o] = map.cell(c)->patches[grid.values[o]].max_z;
  }
  if (std::isnan(floor[static_cast<std::size_t>(start)])) {
    floor[static_cast<std::size_t>(start)] =
        map.cell(t.start)->patches[grid.values[static_cast<std::size_t>(start)]].max_z;
  }

  using Entry = std::pair<float, std::int64_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> open;
  t.distance_m.values[static_cast<std::size_t>(start)] = 0;
  open.push({0.0f, start});
  const float straight = static_cast<float>(grid.cell_m);
  const float diagonal = static_cast<float>(grid.cell_m * std::sqrt(2.0));
  const float step = static_cast<float>(config.max_step_m);
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  while (!open.empty()) {
    const auto [d, o] = open.top();
    open.pop();
    if (d > t.distance_m.values[static_cast<std::size_t>(o)]) continue;
    const int i = static_cast<int>(o % grid.cols), j = static_cast<int>(o / grid.cols);
    const float z = floor[static_cast<std::size_t>(o)];
    for (int n = 0; n < 8; ++n) {
      const int ni = i + kDx[n], nj = j + kDy[n];
      if (ni < 0 || nj < 0 || ni >= grid.cols || nj >= grid.rows) continue;
      const std::size_t no = static_cast<std::size_t>(nj) * grid.cols + ni;
      const float nz = floor[no];
      if (!(std::abs(nz - z) < step)) continue;  // also refuses NaN: not drivable
      const float nd = d + (n < 4 ? straight : diagonal);
      if (nd < t.distance_m.values[no]) {
        t.distance_m.values[no] = nd;
        t.parent.values[no] = static_cast<std::int32_t>(o);
        open.push({nd, static_cast<std::int64_t>(no)});
      }
    }
  }
  return t;
}

}  // namespace scanplan

#include "scanplan/sim/world_traversability.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>
#include <queue>
#include <stdexcept>

namespace scanplan {
namespace {

constexpr double kProbeStartAboveM = 200.0;
constexpr int kMaxLayers = 16;  // surfaces probed per cell; far more than any world stacks

}  // namespace

WorldTraversability::WorldTraversability(const World& world, const RayCaster& caster,
                                         const TraversabilityOptions& options)
    : world_(world), caster_(caster), options_(options) {
  const Eigen::Vector2d extent = world.bounds_max - world.bounds_min;
  cols_ = std::max(1, static_cast<int>(std::ceil(extent.x() / options.cell_m)));
  rows_ = std::max(1, static_cast<int>(std::ceil(extent.y() / options.cell_m)));
  surfaces_.resize(static_cast<std::size_t>(cols_) * rows_);
  const Eigen::Vector3d down(0, 0, -1);

#pragma omp parallel for schedule(dynamic, 16)
  for (int cell = 0; cell < cols_ * rows_; ++cell) {
    const Eigen::Vector2d c = cell_center(static_cast<std::size_t>(cell));
    // Walk down through every surface at this x-y, counting how many solids the probe is in:
    // only a surface entered from free space is a floor, and its headroom reaches up to where
    // the probe last left a solid (the sky for the topmost). Where the ground coincides with a
    // solid's bottom, the ground may be reported instead of the exit; the count then stays
    // above zero and the ground under the solid is rightly no floor.
    double z = kProbeStartAboveM + world.ground_height(c.x(), c.y());
    double ceiling = std::numeric_limits<double>::infinity();
    int depth = 0;
    auto& out = surfaces_[static_cast<std::size_t>(cell)];
    for (int layer = 0; layer < kMaxLayers; ++layer) {
      const auto hit = caster.cast({c.x(), c.y(), z}, down, 0.0, 1e4);
      if (!hit) break;
      const double hz = z - hit->range;
      if (hit->exiting) {
        depth = std::max(0, depth - 1);
        if (depth == 0) ceiling = hz;
      } else {
        if (depth == 0 && hit->normal.z() >= options.min_normal_z &&
            ceiling - hz >= options.clearance_m) {
          out.push_back(static_cast<float>(hz));
        }
        ++depth;
      }
      // Step just past this surface; into a solid the next hit is its far side.
      z = hz - 1e-4;
    }
  }
}

std::optional<std::size_t> WorldTraversability::cell_of(double x, double y) const {
  if (!world_.in_target_region(x, y)) return std::nullopt;
  const int cx = static_cast<int>(std::floor((x - world_.bounds_min.x()) / options_.cell_m));
  const int cy = static_cast<int>(std::floor((y - world_.bounds_min.y()) / options_.cell_m));
  if (cx < 0 || cy < 0 || cx >= cols_ || cy >= rows_) return std::nullopt;
  return static_cast<std::size_t>(cy) * cols_ + cx;
}

Eigen::Vector2d WorldTraversability::cell_center(std::size_t cell) const {
  const double cx = static_cast<double>(cell % cols_), cy = static_cast<double>(cell / cols_);
  return world_.bounds_min +
         Eigen::Vector2d((cx + 0.5) * options_.cell_m, (cy + 0.5) * options_.cell_m);
}

WorldTraversability::Reach WorldTraversability::reach_from(double x, double y, double z) const {
  const auto start = cell_of(x, y);
  if (!start) throw std::invalid_argument("the start is outside the target region");
  const auto& s = surfaces_[*start];
  const auto near = std::min_element(
      s.begin(), s.end(), [&](float a, float b) { return std::abs(a - z) < std::abs(b - z); });
  if (near == s.end() || std::abs(*near - z) > 0.5) {
    throw std::invalid_argument("the start is not on a surface the robot can stand on");
  }

  Reach r;
  const std::size_t n = surfaces_.size();
  r.z.assign(n, std::numeric_limits<float>::quiet_NaN());
  r.distance_m.assign(n, std::numeric_limits<double>::infinity());
  r.parent.assign(n, -1);
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  r.z[*start] = *near;
  r.distance_m[*start] = 0;
  open.push({0.0, *start});
  static constexpr int kDx[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static constexpr int kDy[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  const double diagonal = std::sqrt(2.0) * options_.cell_m;
  // The surface of `to` a robot standing at height `from_z` can step onto, if any.
  const auto step_onto = [&](std::size_t to, float from_z) -> std::optional<float> {
    for (float h : surfaces_[to]) {
      if (std::abs(h - from_z) < options_.max_step_m) return h;
    }
    return std::nullopt;
  };
  while (!open.empty()) {
    const auto [d, cell] = open.top();
    open.pop();
    if (d > r.distance_m[cell]) continue;
    const int cx = static_cast<int>(cell % cols_), cy = static_cast<int>(cell / cols_);
    for (int k = 0; k < 8; ++k) {
      const int nx = cx + kDx[k], ny = cy + kDy[k];
      if (nx < 0 || ny < 0 || nx >= cols_ || ny >= rows_) continue;
      const std::size_t next = static_cast<std::size_t>(ny) * cols_ + nx;
      const Eigen::Vector2d c = cell_center(next);
      if (!world_.in_target_region(c.x(), c.y())) continue;
      const auto h = step_onto(next, r.z[cell]);
      if (!h) continue;
      // No cutting corners past an obstacle: both side cells must be passable too.
      if (k >= 4 && (!step_onto(static_cast<std::size_t>(cy) * cols_ + nx, r.z[cell]) ||
                     !step_onto(static_cast<std::size_t>(ny) * cols_ + cx, r.z[cell]))) {
        continue;
      }
      const double nd = d + (k >= 4 ? diagonal : options_.cell_m);
      if (nd < r.distance_m[next]) {
        r.distance_m[next] = nd;
        r.z[next] = *h;
        r.parent[next] = static_cast<std::int64_t>(cell);
        open.push({nd, next});
      }
    }
  }
  return r;
}

Pose WorldTraversability::standing_pose(double x, double y, double z, double yaw) const {
  // The robot's wheels span about this much: the slope over that base tilts it.
  constexpr double kHalfBaseM = 0.4;
  const auto height_at = [&](double px, double py) {
    const auto hit = caster_.cast({px, py, z + 1.0}, {0, 0, -1}, 0.0, 2.0);
    return hit && !hit->exiting ? z + 1.0 - hit->range : z;
  };
  const double gx =
      (height_at(x + kHalfBaseM, y) - height_at(x - kHalfBaseM, y)) / (2 * kHalfBaseM);
  const double gy =
      (height_at(x, y + kHalfBaseM) - height_at(x, y - kHalfBaseM)) / (2 * kHalfBaseM);
  // The ground normal in the robot's yaw frame; Ry(pitch)·Rx(roll) must turn z onto it.
  const Eigen::Vector3d n =
      Eigen::AngleAxisd(-yaw, Eigen::Vector3d::UnitZ()) * Eigen::Vector3d(-gx, -gy, 1).normalized();
  Pose p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.yaw = yaw;
  p.roll = -std::asin(std::clamp(n.y(), -1.0, 1.0));
  p.pitch = std::atan2(n.x(), n.z());
  return p;
}

std::vector<std::size_t> WorldTraversability::Reach::path_to(std::size_t cell) const {
  std::vector<std::size_t> path;
  if (!reachable(cell)) return path;
  for (std::int64_t c = static_cast<std::int64_t>(cell); c >= 0; c = parent[c]) {
    path.push_back(static_cast<std::size_t>(c));
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace scanplan

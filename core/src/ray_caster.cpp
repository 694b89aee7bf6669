#include "scanplan/core/ray_caster.hpp"

#include <cmath>
#include <limits>

namespace scanplan {

RayCaster::RayCaster(const World& world)
    : ground_z_(world.ground_z), ground_color_(world.ground_color) {
  boxes_.reserve(world.boxes.size());
  for (const auto& b : world.boxes) {
    boxes_.push_back({(b.min + b.max) / 2, (b.max - b.min) / 2, std::cos(b.yaw), std::sin(b.yaw),
                      b.color});
  }
}

std::optional<RayHit> RayCaster::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                      double min_range, double max_range) const {
  double best = std::numeric_limits<double>::infinity();
  Rgb color{};

  // The ground is a plane seen only from above: a scanner below it sees nothing of it.
  if (dir.z() < 0 && origin.z() > ground_z_) {
    const double t = (ground_z_ - origin.z()) / dir.z();
    if (t >= min_range && t <= max_range) {
      best = t;
      color = ground_color_;
    }
  }

  for (const auto& b : boxes_) {
    // Into the box frame: translate to the centre, then rotate by −yaw about z.
    const Eigen::Vector3d o = origin - b.center;
    const Eigen::Vector3d lo(b.cos_yaw * o.x() + b.sin_yaw * o.y(),
                             -b.sin_yaw * o.x() + b.cos_yaw * o.y(), o.z());
    const Eigen::Vector3d ld(b.cos_yaw * dir.x() + b.sin_yaw * dir.y(),
                             -b.sin_yaw * dir.x() + b.cos_yaw * dir.y(), dir.z());
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    bool miss = false;
    for (int a = 0; a < 3 && !miss; ++a) {
      if (std::abs(ld[a]) < 1e-12) {
        miss = std::abs(lo[a]) > b.half[a];
        continue;
      }
      double ta = (-b.half[a] - lo[a]) / ld[a];
      double tb = (b.half[a] - lo[a]) / ld[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
      miss = t0 > t1;
    }
    if (miss) continue;
    // From inside a box the scanner sees its inner walls (t1); otherwise the entry face (t0).
    const double t = t0 >= min_range ? t0 : t1;
    if (t >= min_range && t <= max_range && t < best) {
      best = t;
      color = b.color;
    }
  }
  if (!std::isfinite(best)) return std::nullopt;
  return RayHit{best, color};
}

}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "scanplan/sim/world.hpp"

namespace scanplan {

struct RayHit {
  double range;  // along the unit direction
  Rgb color;
  Eigen::Vector3f normal;  // unit surface normal, turned towards the side the ray came from
  bool exiting = false;    // the ray started inside a solid and this is where it leaves it
};

// Casts rays against a world: its ground (flat or height grid) and every solid in it (boxes,
// cylinders, ellipsoids, tree trunks and canopies, ramps), with exact analytic intersections.
// Solids sit in a bounding-volume hierarchy; the grid ground is marched cell by cell.
// Immutable once built: `cast` may be called from many threads at once, and copies share the
// built structure.
class RayCaster {
 public:
  explicit RayCaster(const World& world);

  // `dir` must be unit length; nothing nearer than `min_range` or beyond `max_range` counts.
  // A ray starting inside a solid sees its inner walls.
  std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                             double min_range, double max_range) const;

  // The same query answered by testing every solid and every ground cell, with no acceleration:
  // the reference the fast path is tested and benchmarked against. Equal ranges, but where two
  // surfaces tie, either may be reported.
  std::optional<RayHit> cast_brute_force(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                         double min_range, double max_range) const;

  // Solids the world became (a tree is two: trunk and canopy).
  std::size_t primitive_count() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace scanplan

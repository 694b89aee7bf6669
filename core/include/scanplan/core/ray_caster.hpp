#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "scanplan/core/world.hpp"

namespace scanplan {

struct RayHit {
  double range;  // along the unit direction
  Rgb color;
};

// Casts rays against the world's ground plane and boxes. Each box is kept in its own frame
// (its yaw undone) so the slab test stays axis-aligned.
class RayCaster {
 public:
  explicit RayCaster(const World& world);

  // `dir` must be unit length; nothing nearer than `min_range` or beyond `max_range` counts.
  std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                             double min_range, double max_range) const;

 private:
  struct LocalBox {
    Eigen::Vector3d center;        // rotation centre in the world
    Eigen::Vector3d half;          // half extents in the box frame
    double cos_yaw, sin_yaw;
    Rgb color;
  };
  double ground_z_;
  Rgb ground_color_;
  std::vector<LocalBox> boxes_;
};

}  // namespace scanplan

#include "scanplan/sim/ray_caster.hpp"

#include <cmath>
#include <cstdint>
#include <vector>

#include "bvh.hpp"
#include "ground_caster.hpp"
#include "ray_primitives.hpp"

namespace scanplan {

using detail::BoxShape;
using detail::ConvexShape;
using detail::CylinderShape;
using detail::EllipsoidShape;
using detail::Ray;
using detail::Span;

namespace {

// Bounding boxes grow by this much so that a ray grazing a face, which the exact test counts
// as a hit, is never culled by rounding in the looser box test.
constexpr double kBoundsPad = 1e-6;

enum class Kind : std::uint8_t { kBox, kCylinder, kEllipsoid, kConvex };

struct Primitive {
  Kind kind;
  std::uint32_t index;  // into the vector of its kind
  Rgb color;
};

// The nearest surface found so far; `t` is also where the ray currently ends.
struct Nearest {
  double t;
  bool found = false;
  Rgb color{};
  Eigen::Vector3d normal{0, 0, 1};
  bool exiting = false;
};

ConvexShape ramp_shape(const WorldRamp& r) {
  ConvexShape c;
  for (int i = 0; i < 3; ++i) {
    c.normals[2 * i] = -Eigen::Vector3d::Unit(i);
    c.offsets[2 * i] = -r.min[i];
    c.normals[2 * i + 1] = Eigen::Vector3d::Unit(i);
    c.offsets[2 * i + 1] = r.max[i];
  }
  // The sloped top replaces the z ≤ max.z face: z − slope·(s − min_s) ≤ min.z, scaled so
  // that its normal is unit length like the others.
  const int a = r.rise_axis;
  const double slope = (r.max.z() - r.min.z()) / (r.max[a] - r.min[a]);
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  n[a] = -slope;
  const double len = n.norm();
  c.normals[5] = n / len;
  c.offsets[5] = (r.min.z() - slope * r.min[a]) / len;
  return c;
}

}  // namespace

struct RayCaster::Impl {
  explicit Impl(const World& world);

  bool intersect(const Primitive& p, const Ray& ray, Span& s) const {
    switch (p.kind) {
      case Kind::kBox:
        return detail::intersect(boxes[p.index], ray, s);
      case Kind::kCylinder:
        return detail::intersect(cylinders[p.index], ray, s);
      case Kind::kEllipsoid:
        return detail::intersect(ellipsoids[p.index], ray, s);
      case Kind::kConvex:
        return detail::intersect(convexes[p.index], ray, s);
    }
    return false;
  }

  // Tests one solid; a visible surface no farther than the current end becomes the nearest.
  void consider(std::uint32_t item, const Ray& ray, double t_min, Nearest& nearest) const {
    const Primitive& p = primitives[item];
    Span s;
    double t;
    Eigen::Vector3d n;
    bool exiting = false;
    if (!intersect(p, ray, s) || !detail::visible_surface(s, t_min, nearest.t, t, n, exiting)) {
      return;
    }
    if (nearest.found && t >= nearest.t) return;
    nearest = {t, true, p.color, n, exiting};
  }

  std::optional<RayHit> finish(const Nearest& nearest) const {
    if (!nearest.found) return std::nullopt;
    return RayHit{nearest.t, nearest.color, nearest.normal.cast<float>(), nearest.exiting};
  }

  detail::GroundCaster ground;
  Rgb ground_color;
  std::vector<BoxShape> boxes;
  std::vector<CylinderShape> cylinders;
  std::vector<EllipsoidShape> ellipsoids;
  std::vector<ConvexShape> convexes;
  std::vector<Primitive> primitives;  // world order: boxes, cylinders, ellipsoids, trees, ramps
  detail::Bvh bvh;
};

RayCaster::Impl::Impl(const World& world)
    : ground(world.ground_z, world.ground_grid), ground_color(world.ground_color) {
  std::vector<Eigen::Vector3d> lo, hi;
  const auto add = [&](Kind kind, std::size_t index, const Rgb& color, const Eigen::Vector3d& l,
                       const Eigen::Vector3d& h) {
    primitives.push_back({kind, static_cast<std::uint32_t>(index), color});
    lo.push_back(l.array() - kBoundsPad);
    hi.push_back(h.array() + kBoundsPad);
  };
  const auto add_cylinder = [&](const CylinderShape& c, const Rgb& color) {
    cylinders.push_back(c);
    add(Kind::kCylinder, cylinders.size() - 1, color, {c.cx - c.radius, c.cy - c.radius, c.z_min},
        {c.cx + c.radius, c.cy + c.radius, c.z_max});
  };
  const auto add_ellipsoid = [&](const Eigen::Vector3d& center, const Eigen::Vector3d& radii,
                                 const Rgb& color) {
    ellipsoids.push_back({center, radii.cwiseInverse()});
    add(Kind::kEllipsoid, ellipsoids.size() - 1, color, center - radii, center + radii);
  };

  for (const auto& b : world.boxes) {
    const BoxShape s{(b.min + b.max) / 2, (b.max - b.min) / 2, std::cos(b.yaw), std::sin(b.yaw)};
    // The turned box's footprint, bounded axis-aligned.
    const double ex = std::abs(s.cos_yaw) * s.half.x() + std::abs(s.sin_yaw) * s.half.y();
    const double ey = std::abs(s.sin_yaw) * s.half.x() + std::abs(s.cos_yaw) * s.half.y();
    const Eigen::Vector3d extent(ex, ey, s.half.z());
    boxes.push_back(s);
    add(Kind::kBox, boxes.size() - 1, b.color, s.center - extent, s.center + extent);
  }
  for (const auto& c : world.cylinders) {
    add_cylinder({c.center.x(), c.center.y(), c.z_min, c.z_max, c.radius_m}, c.color);
  }
  for (const auto& e : world.ellipsoids) add_ellipsoid(e.center, e.radii, e.color);
  for (const auto& t : world.trees) {
    add_cylinder(
        {t.base.x(), t.base.y(), t.base.z(), t.base.z() + t.trunk_height_m, t.trunk_radius_m},
        t.trunk_color);
    add_ellipsoid(t.canopy_center(), t.canopy_radii, t.color);
  }
  for (const auto& r : world.ramps) {
    convexes.push_back(ramp_shape(r));
    add(Kind::kConvex, convexes.size() - 1, r.color, r.min, r.max);
  }
  bvh = detail::Bvh(lo, hi);
}

RayCaster::RayCaster(const World& world) : impl_(std::make_shared<const Impl>(world)) {}

std::size_t RayCaster::primitive_count() const {
  return impl_->primitives.size();
}

std::optional<RayHit> RayCaster::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                                      double min_range, double max_range) const {
  if (!(min_range <= max_range)) return std::nullopt;
  const Impl& im = *impl_;
  const Ray ray(origin, dir);
  Nearest nearest{max_range};
  // The ground first: most downward beams end on it close by, and the shortened ray then
  // prunes nearly every solid.
  double t = 0;
  Eigen::Vector3d n;
  if (im.ground.cast(ray, min_range, max_range, t, n)) nearest = {t, true, im.ground_color, n};
  im.bvh.traverse(ray, min_range, nearest.t,
                  [&](std::uint32_t item) { im.consider(item, ray, min_range, nearest); });
  return im.finish(nearest);
}

std::optional<RayHit> RayCaster::cast_brute_force(const Eigen::Vector3d& origin,
                                                  const Eigen::Vector3d& dir, double min_range,
                                                  double max_range) const {
  if (!(min_range <= max_range)) return std::nullopt;
  const Impl& im = *impl_;
  const Ray ray(origin, dir);
  Nearest nearest{max_range};
  double t = 0;
  Eigen::Vector3d n;
  if (im.ground.cast_every_cell(ray, min_range, max_range, t, n))
    nearest = {t, true, im.ground_color, n};
  for (std::uint32_t i = 0; i < im.primitives.size(); ++i) im.consider(i, ray, min_range, nearest);
  return im.finish(nearest);
}

}  // namespace scanplan

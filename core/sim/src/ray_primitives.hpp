#pragma once

// Exact ray intersections with the world's solid primitives. Each test returns the stretch of
// the ray inside the solid with the outward normals where it enters and leaves; which end the
// scanner sees is decided once, in visible_surface(), for every kind of solid alike.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

namespace scanplan::detail {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Ray {
  Ray(const Eigen::Vector3d& o, const Eigen::Vector3d& d) : origin(o), dir(d) {
    for (int a = 0; a < 3; ++a) inv_dir[a] = 1.0 / d[a];  // ±inf where the ray is parallel
  }
  Eigen::Vector3d origin, dir;  // dir is unit length
  Eigen::Vector3d inv_dir;
};

// The ray is inside the solid for t in [t_in, t_out].
struct Span {
  double t_in = -kInf, t_out = kInf;
  Eigen::Vector3d n_in{0, 0, 0}, n_out{0, 0, 0};  // outward unit normals
};

// The surface the scanner sees: the entry face, or the inner wall when the ray starts inside
// (or its entry lies nearer than t_min). Normals are turned to face the ray.
inline bool visible_surface(const Span& s, double t_min, double t_max, double& t,
                            Eigen::Vector3d& normal, bool& exiting) {
  if (s.t_in >= t_min) {
    if (s.t_in > t_max) return false;
    t = s.t_in;
    normal = s.n_in;
    exiting = false;
    return true;
  }
  if (s.t_out >= t_min && s.t_out <= t_max) {
    t = s.t_out;
    normal = -s.n_out;
    exiting = true;
    return true;
  }
  return false;
}

// A box kept in its own frame (yaw undone about its centre) so the slab test stays axis-aligned.
struct BoxShape {
  Eigen::Vector3d center, half;
  double cos_yaw, sin_yaw;
};

inline bool intersect(const BoxShape& b, const Ray& ray, Span& s) {
  const Eigen::Vector3d o = ray.origin - b.center;
  const Eigen::Vector3d lo(b.cos_yaw * o.x() + b.sin_yaw * o.y(),
                           -b.sin_yaw * o.x() + b.cos_yaw * o.y(), o.z());
  const Eigen::Vector3d ld(b.cos_yaw * ray.dir.x() + b.sin_yaw * ray.dir.y(),
                           -b.sin_yaw * ray.dir.x() + b.cos_yaw * ray.dir.y(), ray.dir.z());
  int axis_in = -1, axis_out = -1;
  double sign_in = 0, sign_out = 0;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(ld[a]) < 1e-12) {
      if (std::abs(lo[a]) > b.half[a]) return false;
      continue;
    }
    const double inv = 1.0 / ld[a];
    const double t_near = (-std::copysign(b.half[a], ld[a]) - lo[a]) * inv;
    const double t_far = (std::copysign(b.half[a], ld[a]) - lo[a]) * inv;
    if (t_near > s.t_in) {
      s.t_in = t_near;
      axis_in = a;
      sign_in = ld[a] > 0 ? -1 : 1;
    }
    if (t_far < s.t_out) {
      s.t_out = t_far;
      axis_out = a;
      sign_out = ld[a] > 0 ? 1 : -1;
    }
  }
  if (s.t_in > s.t_out || axis_in < 0) return false;
  const auto to_world = [&](int axis, double sign) {
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n[axis] = sign;
    return Eigen::Vector3d(b.cos_yaw * n.x() - b.sin_yaw * n.y(),
                           b.sin_yaw * n.x() + b.cos_yaw * n.y(), n.z());
  };
  s.n_in = to_world(axis_in, sign_in);
  s.n_out = to_world(axis_out, sign_out);
  return true;
}

// Both roots of a·t² + b·t + c = 0 (a ≠ 0), ascending, by the form that avoids cancellation.
inline bool solve_quadratic(double a, double b, double c, double& t0, double& t1) {
  const double disc = b * b - 4 * a * c;
  if (disc < 0) return false;
  const double q = -0.5 * (b + std::copysign(std::sqrt(disc), b));
  if (q == 0) {  // b = 0 and c = 0: a double root at zero
    t0 = t1 = 0;
    return true;
  }
  t0 = q / a;
  t1 = c / q;
  if (t0 > t1) std::swap(t0, t1);
  return true;
}

// An upright cylinder with flat caps.
struct CylinderShape {
  double cx, cy, z_min, z_max, radius;
};

inline bool intersect(const CylinderShape& c, const Ray& ray, Span& s) {
  const double ox = ray.origin.x() - c.cx, oy = ray.origin.y() - c.cy;
  const double dx = ray.dir.x(), dy = ray.dir.y();
  const double a = dx * dx + dy * dy;
  const double cc = ox * ox + oy * oy - c.radius * c.radius;
  bool side_in = false, side_out = false;
  if (a < 1e-24) {
    if (cc > 0) return false;  // a vertical ray outside the circle
  } else {
    double t0, t1;
    if (!solve_quadratic(a, 2 * (ox * dx + oy * dy), cc, t0, t1)) return false;
    s.t_in = t0;
    s.t_out = t1;
    side_in = side_out = true;
  }
  bool cap_in = false, cap_out = false;
  const double dz = ray.dir.z();
  if (dz == 0) {
    if (ray.origin.z() < c.z_min || ray.origin.z() > c.z_max) return false;
  } else {
    const double tb = (c.z_min - ray.origin.z()) / dz, tt = (c.z_max - ray.origin.z()) / dz;
    const double t_near = dz > 0 ? tb : tt, t_far = dz > 0 ? tt : tb;
    if (t_near > s.t_in) {
      s.t_in = t_near;
      cap_in = true;
      side_in = false;
    }
    if (t_far < s.t_out) {
      s.t_out = t_far;
      cap_out = true;
      side_out = false;
    }
  }
  if (s.t_in > s.t_out) return false;
  const auto radial = [&](double t) {
    return Eigen::Vector3d(ox + t * dx, oy + t * dy, 0).normalized();
  };
  if (side_in) s.n_in = radial(s.t_in);
  if (cap_in) s.n_in = {0, 0, dz > 0 ? -1.0 : 1.0};
  if (side_out) s.n_out = radial(s.t_out);
  if (cap_out) s.n_out = {0, 0, dz > 0 ? 1.0 : -1.0};
  return true;
}

// An axis-aligned ellipsoid, met by scaling space so that it becomes the unit sphere.
struct EllipsoidShape {
  Eigen::Vector3d center, inv_radii;
};

inline bool intersect(const EllipsoidShape& e, const Ray& ray, Span& s) {
  const Eigen::Vector3d o = (ray.origin - e.center).cwiseProduct(e.inv_radii);
  const Eigen::Vector3d d = ray.dir.cwiseProduct(e.inv_radii);
  double t0, t1;
  if (!solve_quadratic(d.squaredNorm(), 2 * o.dot(d), o.squaredNorm() - 1, t0, t1)) return false;
  s.t_in = t0;
  s.t_out = t1;
  // The gradient of |(p − c)/r|² is 2(p − c)/r²: the scaled point scaled once more.
  s.n_in = (o + t0 * d).cwiseProduct(e.inv_radii).normalized();
  s.n_out = (o + t1 * d).cwiseProduct(e.inv_radii).normalized();
  return true;
}

// A convex solid given as the intersection of half-spaces n·p ≤ d (n unit, pointing out).
struct ConvexShape {
  std::array<Eigen::Vector3d, 6> normals;
  std::array<double, 6> offsets;
};

inline bool intersect(const ConvexShape& c, const Ray& ray, Span& s) {
  for (std::size_t i = 0; i < c.normals.size(); ++i) {
    const double denom = c.normals[i].dot(ray.dir);
    const double num = c.offsets[i] - c.normals[i].dot(ray.origin);
    if (denom == 0) {
      if (num < 0) return false;  // parallel to the plane and outside it
      continue;
    }
    const double t = num / denom;
    if (denom < 0 && t > s.t_in) {
      s.t_in = t;
      s.n_in = c.normals[i];
    } else if (denom > 0 && t < s.t_out) {
      s.t_out = t;
      s.n_out = c.normals[i];
    }
    if (s.t_in > s.t_out) return false;
  }
  return s.t_in <= s.t_out;
}

// Slab test against an axis-aligned bounding box; exactly parallel axes are decided by the
// origin alone, since 0·∞ would otherwise make a NaN of a grazing ray.
inline bool overlaps(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Ray& ray,
                     double t_min, double t_max) {
  for (int a = 0; a < 3; ++a) {
    if (ray.dir[a] == 0) {
      if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return false;
      continue;
    }
    double t0 = (lo[a] - ray.origin[a]) * ray.inv_dir[a];
    double t1 = (hi[a] - ray.origin[a]) * ray.inv_dir[a];
    if (t0 > t1) std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    if (t_min > t_max) return false;
  }
  return true;
}

}  // namespace scanplan::detail

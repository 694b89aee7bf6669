#include "ground_caster.hpp"

#include <algorithm>
#include <cmath>

namespace scanplan::detail {
namespace {

// A root this close outside a cell still belongs to it: neighbouring cells agree on their
// shared edge, and without the slack a crossing exactly on an edge could fall between them.
constexpr double kCellSlack = 1e-9;

}  // namespace

GroundCaster::GroundCaster(double flat_z, const std::optional<HeightGrid>& grid)
    : flat_z_(flat_z), grid_(grid) {}

int GroundCaster::cell_index(int axis, double coord) const {
  const double g = (coord - grid_->origin()[axis]) / grid_->cell_m();
  if (!(g >= 0)) return -1;
  if (g >= count(axis) - 1) return count(axis) - 1;
  return std::min(static_cast<int>(g), count(axis) - 2);
}

void GroundCaster::axis_range(const Ray& ray, int axis, int index, double& t_lo,
                              double& t_hi) const {
  const double lo = index < 0 ? -kInf : line(axis, index);
  const double hi = index >= count(axis) - 1 ? kInf : line(axis, index + 1);
  const double o = ray.origin[axis], d = ray.dir[axis];
  if (d == 0) {
    const bool inside = lo <= o && o <= hi;
    t_lo = inside ? -kInf : kInf;
    t_hi = inside ? kInf : -kInf;
    return;
  }
  t_lo = std::isinf(lo) ? -std::copysign(kInf, d) : (lo - o) / d;
  t_hi = std::isinf(hi) ? std::copysign(kInf, d) : (hi - o) / d;
  if (t_lo > t_hi) std::swap(t_lo, t_hi);
}

bool GroundCaster::cast_cell(const Ray& ray, int col, int row, double t_lo, double t_hi,
                             double t_min, double t_max, double& t, Eigen::Vector3d& normal) const {
  const double lo = std::max(t_lo - kCellSlack, t_min);
  const double hi = std::min(t_hi + kCellSlack, t_max);
  if (!(lo <= hi)) return false;
  const int ca = std::clamp(col, 0, grid_->cols() - 1),
            cb = std::clamp(col + 1, 0, grid_->cols() - 1);
  const int ra = std::clamp(row, 0, grid_->rows() - 1),
            rb = std::clamp(row + 1, 0, grid_->rows() - 1);
  const double h00 = grid_->node(ca, ra), h10 = grid_->node(cb, ra);
  const double h01 = grid_->node(ca, rb), h11 = grid_->node(cb, rb);

  // Cheap rejection first: most cells a ray passes lie wholly below or above it.
  const double oz = ray.origin.z(), dz = ray.dir.z();
  const double z_a = dz == 0 ? oz : oz + lo * dz, z_b = dz == 0 ? oz : oz + hi * dz;
  if (std::min(z_a, z_b) > std::max({h00, h10, h01, h11}) + kCellSlack) return false;
  if (std::max(z_a, z_b) < std::min({h00, h10, h01, h11}) - kCellSlack) return false;

  // Cell coordinates u, v ∈ [0, 1] along the ray; in an edge strip the surface does not vary
  // across the strip, so that coordinate is pinned at 0 rather than run off to infinity.
  const double c = grid_->cell_m();
  const double u0 = ca != cb ? (ray.origin.x() - line(0, ca)) / c : 0.0;
  const double du = ca != cb ? ray.dir.x() / c : 0.0;
  const double v0 = ra != rb ? (ray.origin.y() - line(1, ra)) / c : 0.0;
  const double dv = ra != rb ? ray.dir.y() / c : 0.0;
  // h(u, v) = h00 + e·u + g·v + k·u·v; f(t) = ray z − h is a quadratic in t.
  const double e = h10 - h00, g = h01 - h00, k = h00 - h10 - h01 + h11;
  const double qa = -k * du * dv;
  const double qb = dz - (e * du + g * dv + k * (u0 * dv + v0 * du));
  const double qc = oz - (h00 + e * u0 + g * v0 + k * u0 * v0);

  double roots[2];
  int n_roots = 0;
  if (qa != 0) {
    if (solve_quadratic(qa, qb, qc, roots[0], roots[1])) n_roots = 2;
  } else if (qb != 0) {
    roots[0] = -qc / qb;
    n_roots = 1;
  }
  for (int i = 0; i < n_roots; ++i) {
    const double r = roots[i];
    // Only a crossing going down is the surface seen from above.
    if (r < lo || r > hi || 2 * qa * r + qb > 0) continue;
    t = r;
    const double u = std::clamp(u0 + du * r, 0.0, 1.0), v = std::clamp(v0 + dv * r, 0.0, 1.0);
    const double dh_dx = ca != cb ? (e + k * v) / c : 0.0;
    const double dh_dy = ra != rb ? (g + k * u) / c : 0.0;
    normal = Eigen::Vector3d(-dh_dx, -dh_dy, 1.0).normalized();
    return true;
  }
  return false;
}

bool GroundCaster::cast(const Ray& ray, double t_min, double t_max, double& t,
                        Eigen::Vector3d& normal) const {
  const double oz = ray.origin.z(), dz = ray.dir.z();
  if (!grid_) {
    if (dz >= 0 || oz <= flat_z_) return false;
    const double tp = (flat_z_ - oz) / dz;
    if (tp < t_min || tp > t_max) return false;
    t = tp;
    normal = Eigen::Vector3d::UnitZ();
    return true;
  }
  // Only the stretch of the ray between the lowest and highest node can meet the terrain.
  double t_start = t_min, t_end = t_max;
  if (dz > 0) {
    t_end = std::min(t_end, (grid_->max_height() - oz) / dz + kCellSlack);
  } else if (dz < 0) {
    t_start = std::max(t_start, (grid_->max_height() - oz) / dz - kCellSlack);
    t_end = std::min(t_end, (grid_->min_height() - oz) / dz + kCellSlack);
  } else if (oz > grid_->max_height() || oz < grid_->min_height()) {
    return false;
  }
  if (!(t_start <= t_end)) return false;

  // Grid-cell DDA over the ray's x-y shadow, edge strips included.
  int col = cell_index(0, ray.origin.x() + t_start * ray.dir.x());
  int row = cell_index(1, ray.origin.y() + t_start * ray.dir.y());
  const int step_col = ray.dir.x() > 0 ? 1 : (ray.dir.x() < 0 ? -1 : 0);
  const int step_row = ray.dir.y() > 0 ? 1 : (ray.dir.y() < 0 ? -1 : 0);
  const auto exit_t = [&](int axis, int index, int step) {
    if (step > 0 && index < count(axis) - 1)
      return (line(axis, index + 1) - ray.origin[axis]) / ray.dir[axis];
    if (step < 0 && index > -1) return (line(axis, index) - ray.origin[axis]) / ray.dir[axis];
    return kInf;
  };
  double t_cur = t_start;
  for (;;) {
    const double tx = exit_t(0, col, step_col), ty = exit_t(1, row, step_row);
    const double t_next = std::min(tx, ty);
    if (cast_cell(ray, col, row, t_cur, std::min(t_next, t_end), t_min, t_max, t, normal))
      return true;
    if (t_next >= t_end) return false;
    if (tx <= ty) col += step_col;
    if (ty <= tx) row += step_row;
    t_cur = t_next;
  }
}

bool GroundCaster::cast_every_cell(const Ray& ray, double t_min, double t_max, double& t,
                                   Eigen::Vector3d& normal) const {
  if (!grid_) return cast(ray, t_min, t_max, t, normal);
  bool found = false;
  double best = t_max;
  for (int col = -1; col < grid_->cols(); ++col) {
    double x_lo, x_hi;
    axis_range(ray, 0, col, x_lo, x_hi);
    for (int row = -1; row < grid_->rows(); ++row) {
      double y_lo, y_hi;
      axis_range(ray, 1, row, y_lo, y_hi);
      double tc;
      Eigen::Vector3d nc;
      if (cast_cell(ray, col, row, std::max(x_lo, y_lo), std::min(x_hi, y_hi), t_min, best, tc,
                    nc)) {
        found = true;
        best = tc;
        t = tc;
        normal = nc;
      }
    }
  }
  return found;
}

}  // namespace scanplan::detail

#include "scanplan/planning/registrability.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <vector>

#include "digest.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan {

namespace {

// The unit direction through the middle of view sector s.
const Eigen::Vector2d& sector_direction(int s) {
  static const std::array<Eigen::Vector2d, kViewSectors> directions = [] {
    std::array<Eigen::Vector2d, kViewSectors> d;
    for (int k = 0; k < kViewSectors; ++k) {
      const double a = (k + 0.5) * 2 * M_PI / kViewSectors;
      d[static_cast<std::size_t>(k)] = {std::cos(a), std::sin(a)};
    }
    return d;
  }();
  return directions[static_cast<std::size_t>(s)];
}

// Σ e eᵀ over the offsets: how the cells spread about the cell they are taken from.
Eigen::Matrix2d spread_of(const std::vector<Eigen::Vector2d>& offsets) {
  Eigen::Matrix2d spread = Eigen::Matrix2d::Zero();
  for (const Eigen::Vector2d& e : offsets) spread += e * e.transpose();
  return spread;
}

}  // namespace

RegistrabilityField::RegistrabilityField(const MlsMap& anchored, CellIndex origin, int cols,
                                         int rows, const RegistrabilityConfig& config)
    : config_(config),
      cell_m_(anchored.cell_m()),
      cols_(cols),
      rows_(rows),
      cells_(static_cast<std::size_t>(cols) * static_cast<std::size_t>(rows)) {
  // The share of a cell within inlier_distance_m of one point in it.
  const double near_area =
      M_PI * config.inlier_distance_m * config.inlier_distance_m / (cell_m_ * cell_m_);
  const auto cell_offset = [cols](int i, int j) {
    return static_cast<std::size_t>(j) * static_cast<std::size_t>(cols) +
           static_cast<std::size_t>(i);
  };
  std::vector<ViewSectors> seen(cells_.size(), 0);  // per wall cell: its walls' seen_from
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      const MlsCell* c = anchored.cell({origin.x + i, origin.y + j});
      if (!c) continue;
      Cell& out = cells_[static_cast<std::size_t>(j) * static_cast<std::size_t>(cols) +
                         static_cast<std::size_t>(i)];
      out.mapped = 1;
      if (c->interpolated) continue;  // heights between beams: no point to match against
      double points = 0;
      for (const SurfacePatch& p : *c) {
        points += p.count;
        if (p.extent() >= config.wall_min_extent_m) {
          out.wall = 1;
          seen[cell_offset(i, j)] |= p.seen_from;
        }
      }
      // In sixteenths: a cell a new scan adds a few points to keeps its odds once it holds a
      // dozen, so the evaluations that read it stay reusable between plans (GainMemo).
      out.odds = static_cast<float>(std::round(16 * (1 - std::exp(-points * near_area))) / 16);
    }
  }
  // A wall's normal is the direction across the walls around it: the minor axis of their
  // cells' spread. Where they spread evenly (a post, a corner, a thick block) every direction
  // is fixed alike.
  const int r = std::max(1, config.wall_radius_cells);
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < cols; ++i) {
      Cell& w = cells_[cell_offset(i, j)];
      if (!w.wall) continue;
      const WallLine near = wall_line(i, j, r);
      std::optional<Eigen::Vector2d> normal = near.normal;
      if (!normal && config.wall_line_radius_cells > r) {
        normal = wall_line(i, j, config.wall_line_radius_cells, 1.0).normal;
        // A lone cell: a wall met end-on, or a post in a row.
        if (normal && near.cells < 3 && !seen_along(seen[cell_offset(i, j)], *normal)) {
          normal.reset();
        }
      }
      Eigen::Matrix2d t = 0.5 * Eigen::Matrix2d::Identity();
      if (normal) t = *normal * normal->transpose();
      if (config.sided_walls) w.visible_from = visible_from(seen[cell_offset(i, j)], normal);
      if (!normal && config.corner_faces) set_faces(w, seen[cell_offset(i, j)], i, j);
      w.t_xx = static_cast<float>(t(0, 0));
      w.t_xy = static_cast<float>(t(0, 1));
      w.t_yy = static_cast<float>(t(1, 1));
    }
  }
}

std::vector<Eigen::Vector2d> RegistrabilityField::wall_offsets(int i, int j, int radius) const {
  std::vector<Eigen::Vector2d> offsets;
  for (int dj = -radius; dj <= radius; ++dj) {
    for (int di = -radius; di <= radius; ++di) {
      const int x = i + di, y = j + dj;
      if (x < 0 || y < 0 || x >= cols_ || y >= rows_ || di * di + dj * dj > radius * radius) {
        continue;
      }
      if (cells_[static_cast<std::size_t>(y) * static_cast<std::size_t>(cols_) +
                 static_cast<std::size_t>(x)]
              .wall) {
        offsets.emplace_back(di, dj);
      }
    }
  }
  return offsets;
}

std::optional<std::pair<Eigen::Vector2d, Eigen::Vector2d>> RegistrabilityField::corner_arms(
    int i, int j, int radius) const {
  std::vector<Eigen::Vector2d> offsets = wall_offsets(i, j, radius);
  std::erase_if(offsets, [](const Eigen::Vector2d& e) { return e.isZero(); });
  // Two arms spread the cells about evenly; the end of a wall two cells thick, which looks like
  // a corner up close, spreads them along itself.
  const Eigen::Vector2d l =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(spread_of(offsets), Eigen::EigenvaluesOnly)
          .eigenvalues();
  if (offsets.size() < 4 || l[1] > 4 * l[0]) return std::nullopt;
  // An arm: the wall cells near a ray from the cell (within 0.75 of a cell of it), their mean
  // direction.
  const auto arm = [&](const Eigen::Vector2d& u, Eigen::Vector2d& mean) {
    int n = 0;
    mean.setZero();
    for (const Eigen::Vector2d& e : offsets) {
      if (e.dot(u) >= 0.5 && std::abs(e.x() * u.y() - e.y() * u.x()) <= 0.75) {
        mean += e.normalized();
        ++n;
      }
    }
    if (n > 0) mean.normalize();
    return n;
  };
  const double apart = std::cos(deg2rad(50));  // the arms at least 50° apart
  int best1 = 0, best2 = 0;
  Eigen::Vector2d u1, u2, mean;
  for (const Eigen::Vector2d& e : offsets) {
    const int n = arm(e.normalized(), mean);
    if (n > best1) best1 = n, u1 = mean;
  }
  if (best1 < 2) return std::nullopt;
  for (const Eigen::Vector2d& e : offsets) {
    const Eigen::Vector2d u = e.normalized();
    if (std::abs(u.dot(u1)) > apart) continue;
    const int n = arm(u, mean);
    if (n > best2) best2 = n, u2 = mean;
  }
  if (best2 < 2 || std::abs(u1.dot(u2)) > apart) return std::nullopt;
  // The corner ends both arms: a wall going on past it (a T, a crossing) is no corner's face.
  if (arm(-u1, mean) > 1 || arm(-u2, mean) > 1) return std::nullopt;
  // Nothing between the arms but the arms: the corner of a solid block (rubble, a thick pier)
  // holds wall cells inside the angle too, and is no two faces.
  const double turn = u1.x() * u2.y() - u1.y() * u2.x();
  for (const Eigen::Vector2d& e : offsets) {
    const double a = u1.x() * e.y() - u1.y() * e.x(), b = e.x() * u2.y() - e.y() * u2.x();
    const bool between = a * turn > 0 && b * turn > 0;
    const bool on_arm = std::abs(a) <= 0.75 * e.norm() || std::abs(b) <= 0.75 * e.norm();
    if (between && !on_arm) return std::nullopt;
  }
  return std::make_pair(u1, u2);
}

void RegistrabilityField::set_faces(Cell& w, ViewSectors seen, int i, int j) const {
  if (seen == 0) return;  // where its scanners stood is not known: nor which way it juts
  const auto arms = corner_arms(i, j, std::max(2, config_.wall_radius_cells + 2));
  if (!arms) return;
  const auto& [u1, u2] = *arms;
  // A face's outward normal is across its arm, away from the other arm where the corner juts out
  // (its scanners stood outside the angle between the arms), towards it where it is recessed.
  int inside = 0, outside = 0;
  for (int s = 0; s < kViewSectors; ++s) {
    if (!(seen >> s & 1)) continue;
    const Eigen::Vector2d& d = sector_direction(s);
    ++(d.dot(u1) > 0 && d.dot(u2) > 0 ? inside : outside);
  }
  const double towards = inside > outside ? 1.0 : -1.0;
  Eigen::Vector2d n1(-u1.y(), u1.x()), n2(-u2.y(), u2.x());
  if (towards * n1.dot(u2) < 0) n1 = -n1;
  if (towards * n2.dot(u1) < 0) n2 = -n2;
  w.n1x = static_cast<float>(n1.x());
  w.n1y = static_cast<float>(n1.y());
  w.n2x = static_cast<float>(n2.x());
  w.n2y = static_cast<float>(n2.y());
  w.faces = 1;
}

RegistrabilityField::WallLine RegistrabilityField::wall_line(
    int i, int j, int radius, std::optional<double> max_off_line) const {
  WallLine line;
  const std::vector<Eigen::Vector2d> offsets = wall_offsets(i, j, radius);
  line.cells = static_cast<int>(offsets.size());
  if (line.cells < 3) return line;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> eig(spread_of(offsets));
  // The spread is taken about the cell itself, so its smaller eigenvalue per cell is how far off
  // a line through the cell the others lie.
  const Eigen::Vector2d& l = eig.eigenvalues();
  if (l[1] <= 4 * l[0]) return line;
  if (max_off_line) {
    if (l[0] > *max_off_line * line.cells) return line;
    // On both sides: the long face of a corner whose other face is short lies on one.
    const Eigen::Vector2d along = eig.eigenvectors().col(1);
    bool before = false, after = false;
    for (const Eigen::Vector2d& d : offsets) {
      before = before || d.dot(along) <= -1;
      after = after || d.dot(along) >= 1;
    }
    if (!before || !after) return line;
  }
  line.normal = eig.eigenvectors().col(0);
  return line;
}

bool RegistrabilityField::seen_along(ViewSectors seen, const Eigen::Vector2d& normal) {
  if (seen == 0) return false;
  for (int s = 0; s < kViewSectors; ++s) {
    // Within 30° of the line (a sector's middle, so up to 41° for a scanner at its edge).
    if ((seen >> s & 1) && std::abs(normal.dot(sector_direction(s))) > 0.5) {
      return false;
    }
  }
  return true;
}

ViewSectors RegistrabilityField::visible_from(ViewSectors seen,
                                              const std::optional<Eigen::Vector2d>& normal) {
  if (seen == 0) return 0xFFFF;  // measured without its scanner: seen from anywhere
  if (!normal) {
    // A corner or a post: met from within a right angle of where it was seen, the face the
    // scanner met turned towards it.
    ViewSectors visible = 0;
    for (int c = 0; c < kViewSectors; ++c) {
      for (int s = 0; s < kViewSectors; ++s) {
        if ((seen >> s & 1) && sector_direction(c).dot(sector_direction(s)) > -1e-9) {
          visible |= static_cast<ViewSectors>(1u << c);
        }
      }
    }
    return visible;
  }
  // A straight wall: from the side its scanners stood on. A sector the wall's line passes
  // through (its middle within half a sector of the line) lies on both sides.
  const double straddles = std::sin(M_PI / kViewSectors);
  bool sides[2] = {false, false};  // [0]: along the normal, [1]: against it
  for (int s = 0; s < kViewSectors; ++s) {
    const double across = normal->dot(sector_direction(s));
    if ((seen >> s & 1) && std::abs(across) >= straddles) sides[across < 0] = true;
  }
  // Seen only along the wall: which side is not known.
  if (!sides[0] && !sides[1]) return 0xFFFF;
  ViewSectors visible = 0;
  for (int c = 0; c < kViewSectors; ++c) {
    const double across = normal->dot(sector_direction(c));
    if (std::abs(across) < straddles || sides[across < 0]) {
      visible |= static_cast<ViewSectors>(1u << c);
    }
  }
  return visible;
}

void RegistrabilityField::Forecast::add(std::uint32_t o, int di, int dj) {
  const RegistrabilityField& f = field_;
  const double px = di * f.cell_m_, py = dj * f.cell_m_;
  const double r2 = px * px + py * py;
  const double near2 = f.config_.near_range_m * f.config_.near_range_m;
  const double w = 1.0 / std::max(r2, near2);
  seen_ += w;
  const Cell& c = f.cells_[o];
  if (!c.mapped) return;
  mapped_ += w;
  on_map_ += w * c.odds;
  if (!c.wall) return;
  // A face the map holds from the other side: this scan meets another face here, or none.
  if (!(c.visible_from >> view_sector(static_cast<float>(-px), static_cast<float>(-py)) & 1)) {
    return;
  }
  double txx = c.t_xx, txy = c.t_xy, tyy = c.t_yy;
  if (c.faces) {
    // A corner: the faces this scan meets (it stands at −p from the cell), a cell or more out
    // from their lines, which pass through the cell's centre only to within a cell (a face met
    // at grazing holds few points anyway).
    const double margin = f.cell_m_;
    const bool one = c.n1x * -px + c.n1y * -py > margin;
    const bool two = c.n2x * -px + c.n2y * -py > margin;
    if (!one && !two) return;
    const double k = one && two ? 0.5 : 1.0;
    txx = k * ((one ? c.n1x * c.n1x : 0.0) + (two ? c.n2x * c.n2x : 0.0));
    txy = k * ((one ? c.n1x * c.n1y : 0.0) + (two ? c.n2x * c.n2y : 0.0));
    tyy = k * ((one ? c.n1y * c.n1y : 0.0) + (two ? c.n2y * c.n2y : 0.0));
  }
  // The wall fixes the pose along its normal n: a row (n, p⊥·n) of the x, y, yaw Jacobian,
  // summed over the normals T = Σ n nᵀ stands for.
  const double qx = -py, qy = px;  // p⊥
  const double tqx = txx * qx + txy * qy, tqy = txy * qx + tyy * qy;
  t_xx_ += w * txx;
  t_xy_ += w * txy;
  t_yy_ += w * tyy;
  tp_x_ += w * tqx;
  tp_y_ += w * tqy;
  ptp_ += w * (qx * tqx + qy * tqy);
  r2_ += w * r2;
  walls_ += w;
}

std::uint64_t RegistrabilityField::digest() const {
  using digest::mix;
  const RegistrabilityConfig& c = config_;
  std::uint64_t h = mix(std::uint64_t{0xF1E1D}, static_cast<std::uint64_t>(c.enabled));
  h = mix(h, static_cast<std::uint64_t>(c.sided_walls));
  h = mix(h, static_cast<std::uint64_t>(c.wall_line_radius_cells));
  h = mix(h, static_cast<std::uint64_t>(c.corner_faces));
  for (const double v : {c.min_overlap_share, c.min_pose_fixing, c.floor_share, c.near_range_m,
                         c.inlier_distance_m, cell_m_})
    h = mix(h, v);
  return h;
}

std::uint64_t RegistrabilityField::cell_digest(std::size_t offset) const {
  using digest::mix;
  const Cell& c = cells_[offset];
  const std::uint64_t flags = c.mapped | (std::uint64_t{c.wall} << 8);
  const std::uint64_t h =
      mix(mix(mix(mix(mix(std::uint64_t{0xCE11}, flags), c.odds), c.t_xx), c.t_xy), c.t_yy);
  const std::uint64_t faces = mix(mix(mix(mix(h, c.n1x), c.n1y), c.n2x), c.n2y);
  return mix(mix(faces, std::uint64_t{c.faces}), std::uint64_t{c.visible_from});
}

Registrability RegistrabilityField::Forecast::result() const {
  const RegistrabilityConfig& cfg = field_.config_;
  Registrability out;
  out.overlap_share = seen_ > 0 ? on_map_ / seen_ : 0.0;
  if (walls_ > 0 && mapped_ > 0) {
    const double L = std::max(std::sqrt(r2_ / walls_), 1e-6);
    Eigen::Matrix3d info;
    info << t_xx_, t_xy_, tp_x_ / L, t_xy_, t_yy_, tp_y_ / L, tp_x_ / L, tp_y_ / L, ptp_ / (L * L);
    info /= mapped_;
    out.pose_fixing =
        std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(info, Eigen::EigenvaluesOnly)
                          .eigenvalues()[0]);
  }
  const double share =
      std::min(out.overlap_share / cfg.min_overlap_share, out.pose_fixing / cfg.min_pose_fixing);
  out.factor = share >= 1 || !cfg.enabled ? 1.0 : std::max(cfg.floor_share, share * share);
  return out;
}

namespace {

// The share of 3σ of the pose after driving d metres that the search reaches.
double reached(const DriveDrift& drift, double d, const RegistrabilityConfig& config) {
  // A heading already off swings the whole drive sideways.
  const double swing = d * deg2rad(drift.start_yaw_deg);
  const double xy = std::sqrt(drift.start_xy_m * drift.start_xy_m +
                              std::pow(drift.xy_per_m * d, 2) + swing * swing);
  const double yaw = std::hypot(drift.start_yaw_deg, drift.yaw_deg_per_m * d);
  double s = 1;
  if (xy > 0) s = std::min(s, config.reach_xy_m / (3 * xy));
  if (yaw > 0) s = std::min(s, config.reach_yaw_deg / (3 * yaw));
  return s;
}

}  // namespace

double drive_reach(const DriveDrift& drift, double travel_m, const RegistrabilityConfig& config) {
  // Relative to staying put: a robot already beyond the search (its latest scan not placed) is
  // no less likely to be placed after a short drive, and a long one still costs it.
  return reached(drift, std::max(0.0, travel_m), config) / reached(drift, 0, config);
}

}  // namespace scanplan

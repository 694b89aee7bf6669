#include "scanplan/registration/pose_search.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/voxel_filter.hpp"

namespace scanplan {
namespace {

// A grid more cells than this is coarsened: a target spread over kilometres is not a scan.
constexpr std::size_t kMaxCells = std::size_t{1} << 26;

// How likely a point is at each cube of the target's bounding box: 255·exp(−d²/2σ²) with d the
// distance from the cube to the nearest cube holding a target point, centre to centre (σ = the
// cube side), within two cubes of it.
class LikelihoodGrid {
 public:
  LikelihoodGrid(const PointCloud& target, double cell_m) {
    const PointCloud thin = voxel_downsample(target, cell_m);
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector3f hi = -lo;
    for (const auto& p : thin.points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    if (thin.empty()) return;
    cell_ = static_cast<float>(cell_m);
    for (;;) {
      origin_ = lo - Eigen::Vector3f::Constant(3 * cell_);
      const Eigen::Vector3f extent = (hi - origin_) / cell_;
      nx_ = static_cast<int>(extent.x()) + 4;
      ny_ = static_cast<int>(extent.y()) + 4;
      nz_ = static_cast<int>(extent.z()) + 4;
      if (static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) *
              static_cast<std::size_t>(nz_) <=
          kMaxCells) {
        break;
      }
      cell_ *= 2;
    }
    value_.assign(static_cast<std::size_t>(nx_) * static_cast<std::size_t>(ny_) *
                      static_cast<std::size_t>(nz_),
                  0);
    // The likelihood of a cube from a point in the cube `offset` away, centre to centre: the
    // point is taken at its cube's centre, which a half-cube blur does not notice.
    std::uint8_t kernel[5][5][5];
    for (int z = 0; z < 5; ++z) {
      for (int y = 0; y < 5; ++y) {
        for (int x = 0; x < 5; ++x) {
          const double d_sq = (x - 2) * (x - 2) + (y - 2) * (y - 2) + (z - 2) * (z - 2);
          kernel[z][y][x] = static_cast<std::uint8_t>(255.0 * std::exp(-0.5 * d_sq));
        }
      }
    }
    for (const auto& p : thin.points) {
      const Eigen::Vector3i c = cube(p);
      for (int z = 0; z < 5; ++z) {
        for (int y = 0; y < 5; ++y) {
          std::uint8_t* row = &value_[index(c.x() - 2, c.y() + y - 2, c.z() + z - 2)];
          for (int x = 0; x < 5; ++x) row[x] = std::max(row[x], kernel[z][y][x]);
        }
      }
    }
  }

  bool empty() const { return value_.empty(); }
  float cell() const { return cell_; }

  // The cube holding p, as integer coordinates (may lie outside the grid).
  Eigen::Vector3i cube(const Eigen::Vector3f& p) const {
    const Eigen::Vector3f f = (p - origin_) / cell_;
    return {static_cast<int>(std::floor(f.x())), static_cast<int>(std::floor(f.y())),
            static_cast<int>(std::floor(f.z()))};
  }

  // The sums of the likelihoods of `cubes` shifted by every (dx0 + i, dy0 + j) cubes, |i|, |j| ≤
  // steps, row by row (j, then i); 0 outside the grid. Each cube meets one run of the grid along
  // x per row of shifts, so the shifts are summed from contiguous memory: the search is one
  // sweep of a window per cube instead of a scattered read per cube and shift.
  void score_window(const std::vector<Eigen::Vector3i>& cubes, int dx0, int dy0, int steps,
                    std::vector<std::uint32_t>& sums) const {
    const int w = 2 * steps + 1;
    sums.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(w), 0);
    for (const auto& c : cubes) {
      const int z = c.z();
      if (z < 0 || z >= nz_) continue;
      const int x0 = c.x() + dx0 - steps;  // the x the first shift of a row reads
      const int i0 = std::max(0, -x0), i1 = std::min(w, nx_ - x0);
      if (i0 >= i1) continue;
      for (int j = 0; j < w; ++j) {
        const int y = c.y() + dy0 - steps + j;
        if (y < 0 || y >= ny_) continue;
        const std::uint8_t* row = &value_[index(0, y, z)];
        std::uint32_t* out = &sums[static_cast<std::size_t>(j) * static_cast<std::size_t>(w)];
        for (int i = i0; i < i1; ++i) out[i] += row[x0 + i];
      }
    }
  }

 private:
  std::size_t index(int x, int y, int z) const {
    return (static_cast<std::size_t>(z) * static_cast<std::size_t>(ny_) +
            static_cast<std::size_t>(y)) *
               static_cast<std::size_t>(nx_) +
           static_cast<std::size_t>(x);
  }

  Eigen::Vector3f origin_ = Eigen::Vector3f::Zero();
  float cell_ = 1;
  int nx_ = 0, ny_ = 0, nz_ = 0;
  std::vector<std::uint8_t> value_;
};

struct Candidate {
  double dx, dy, yaw;  // metres, metres, radians: the offset from the initial pose
  double score;
};

double offset_weight(const PoseSearchConfig& c, double metres, double radians) {
  double e = 0;
  if (c.prior_sigma_xy_m > 0) e += std::pow(metres / c.prior_sigma_xy_m, 2);
  if (c.prior_sigma_yaw_deg > 0) e += std::pow(rad2deg(radians) / c.prior_sigma_yaw_deg, 2);
  return std::exp(-0.5 * e);
}

// The best of `found` that lie apart from each other, best first (by score times the prior).
std::vector<Candidate> distinct_peaks(const std::vector<Candidate>& found, std::size_t count,
                                      const PoseSearchConfig& config) {
  const double min_m = config.min_separation_m, min_rad = deg2rad(config.min_separation_deg);
  // Each candidate's rank once (thousands of them, an exp each), not once per comparison.
  std::vector<std::pair<double, const Candidate*>> ranked;
  ranked.reserve(found.size());
  for (const Candidate& c : found) {
    ranked.emplace_back(c.score * offset_weight(config, std::hypot(c.dx, c.dy), c.yaw), &c);
  }
  std::sort(ranked.begin(), ranked.end(),
            [](const auto& a, const auto& b) { return a.first > b.first; });
  std::vector<Candidate> out;
  for (const auto& [rank, c] : ranked) {
    if (out.size() >= count) break;
    const bool separate = std::all_of(out.begin(), out.end(), [&](const Candidate& o) {
      return std::hypot(c->dx - o.dx, c->dy - o.dy) >= min_m ||
             std::abs(std::remainder(c->yaw - o.yaw, 2 * M_PI)) >= min_rad;
    });
    if (separate) out.push_back(*c);
  }
  return out;
}

// The source points placed by the initial pose turned by `yaw` about `centre` (the source
// origin), as cubes of `grid`.
std::vector<Eigen::Vector3i> turned_cubes(const std::vector<Eigen::Vector3f>& placed,
                                          const Eigen::Vector3f& centre, double yaw,
                                          const LikelihoodGrid& grid) {
  const Eigen::Matrix3f R =
      Eigen::AngleAxisf(static_cast<float>(yaw), Eigen::Vector3f::UnitZ()).toRotationMatrix();
  std::vector<Eigen::Vector3i> cubes;
  cubes.reserve(placed.size());
  for (const auto& p : placed) cubes.push_back(grid.cube(R * (p - centre) + centre));
  return cubes;
}

// Every shift within ±steps cubes at each of `yaws`, around (dx0, dy0) cubes.
void scan_window(const LikelihoodGrid& grid, const std::vector<Eigen::Vector3f>& placed,
                 const Eigen::Vector3f& centre, const std::vector<double>& yaws, int dx0, int dy0,
                 int steps, std::vector<Candidate>& out) {
  const double n = static_cast<double>(std::max<std::size_t>(placed.size(), 1)) * 255.0;
  const int w = 2 * steps + 1;
  std::vector<std::uint32_t> sums;
  for (const double yaw : yaws) {
    grid.score_window(turned_cubes(placed, centre, yaw, grid), dx0, dy0, steps, sums);
    for (int j = -steps; j <= steps; ++j) {
      for (int i = -steps; i <= steps; ++i) {
        const double s = sums[static_cast<std::size_t>((j + steps) * w + i + steps)] / n;
        out.push_back({(dx0 + i) * static_cast<double>(grid.cell()),
                       (dy0 + j) * static_cast<double>(grid.cell()), yaw, s});
      }
    }
  }
}

std::vector<double> yaw_steps(double centre, double half_range, double step) {
  std::vector<double> out;
  const int n = static_cast<int>(std::floor(half_range / step + 1e-9));
  for (int k = -n; k <= n; ++k) out.push_back(centre + k * step);
  return out;
}

}  // namespace

double prior_weight(const PoseSearchConfig& config, const Eigen::Isometry3d& initial,
                    const Eigen::Isometry3d& pose) {
  const Eigen::Isometry3d off = initial.inverse() * pose;
  const Eigen::Vector3d x = off.linear() * Eigen::Vector3d::UnitX();
  return offset_weight(config, (pose.translation() - initial.translation()).head<2>().norm(),
                       std::atan2(x.y(), x.x()));
}

std::vector<PoseHypothesis> search_poses(const PointCloud& target, const PointCloud& source,
                                         const Eigen::Isometry3d& initial,
                                         const PoseSearchConfig& config) {
  if (target.empty() || source.empty() || !(config.cell_m > 0) || !(config.yaw_step_deg > 0)) {
    return {};
  }
  // Coarse: twice the cube and twice the turn step over the whole range; fine: the configured
  // resolution around the coarse peaks.
  const LikelihoodGrid coarse(target, 2 * config.cell_m);
  const LikelihoodGrid fine(target, config.cell_m);
  if (coarse.empty() || fine.empty()) return {};

  PointCloud thin = voxel_downsample(source, config.source_voxel_m);
  std::vector<Eigen::Vector3f> placed;
  const std::size_t keep = static_cast<std::size_t>(std::max(config.max_source_points, 1));
  const std::size_t stride = std::max<std::size_t>(1, (thin.size() + keep - 1) / keep);
  const Eigen::Isometry3f T = initial.cast<float>();
  for (std::size_t i = 0; i < thin.size(); i += stride) placed.push_back(T * thin.points[i]);
  const Eigen::Vector3f centre = T.translation();

  const double step = deg2rad(config.yaw_step_deg);
  const std::size_t wanted = static_cast<std::size_t>(std::max(config.hypotheses, 1));
  std::vector<Candidate> found;
  const int reach = static_cast<int>(std::ceil(config.xy_range_m / coarse.cell()));
  scan_window(coarse, placed, centre, yaw_steps(0, deg2rad(config.yaw_range_deg), 2 * step), 0, 0,
              reach, found);
  const std::vector<Candidate> rough = distinct_peaks(found, 3 * wanted, config);

  std::vector<Candidate> refined;
  for (const Candidate& c : rough) {
    std::vector<Candidate> local;
    const int cx = static_cast<int>(std::lround(c.dx / fine.cell()));
    const int cy = static_cast<int>(std::lround(c.dy / fine.cell()));
    scan_window(fine, placed, centre, yaw_steps(c.yaw, 2 * step, step), cx, cy, 2, local);
    refined.push_back(*std::max_element(
        local.begin(), local.end(),
        [](const Candidate& a, const Candidate& b) { return a.score < b.score; }));
  }
  std::vector<PoseHypothesis> out;
  for (const Candidate& c : distinct_peaks(refined, wanted, config)) {
    Eigen::Isometry3d move = Eigen::Isometry3d::Identity();
    const Eigen::Vector3d pivot = centre.cast<double>();
    move.translate(pivot + Eigen::Vector3d(c.dx, c.dy, 0));
    move.rotate(Eigen::AngleAxisd(c.yaw, Eigen::Vector3d::UnitZ()));
    move.translate(-pivot);
    out.push_back({move * initial, c.score});
  }
  return out;
}

}  // namespace scanplan

#include "scanplan/mission/view_check.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace scanplan {

namespace {

// The predicted range image: the nearest range per bin of azimuth and elevation.
class RangeImage {
 public:
  explicit RangeImage(double bin_deg)
      : per_rad_(180.0 / (M_PI * bin_deg)),
        cols_(static_cast<int>(std::ceil(2 * M_PI * per_rad_))),
        rows_(static_cast<int>(std::ceil(M_PI * per_rad_)) + 1),
        range_(size(), std::numeric_limits<float>::infinity()) {}

  // Azimuth in [0, 2π), elevation in [0, π] from straight down.
  struct Direction {
    double az, el;
  };
  static Direction direction_of(const Eigen::Vector3f& d) {
    return {std::atan2(d.y(), d.x()) + M_PI,
            std::atan2(d.z(), std::hypot(d.x(), d.y())) + M_PI / 2};
  }
  std::size_t bin_of(Direction a) const { return offset(col(a.az), row(a.el)); }
  std::size_t size() const {
    return static_cast<std::size_t>(cols_) * static_cast<std::size_t>(rows_);
  }
  // Marks the bins within `radius` (radians of elevation; of azimuth widened by 1 / cos of the
  // elevation) of direction a as `range` away at most.
  void cover(Direction a, double radius, float range) {
    const double widen = 1.0 / std::max(std::sin(a.el), 0.05);  // cos of the elevation
    const double half_az = std::min(M_PI, radius * widen);
    const int c0 = static_cast<int>(std::floor((a.az - half_az) * per_rad_));
    const int c1 = static_cast<int>(std::floor((a.az + half_az) * per_rad_));
    for (int r = row(a.el - radius); r <= row(a.el + radius); ++r) {
      for (int c = c0; c <= c1; ++c) {
        float& at = range_[offset((c % cols_ + cols_) % cols_, r)];  // azimuth wraps around
        at = std::min(at, range);
      }
    }
  }
  float nearest(std::size_t bin) const { return range_[bin]; }

 private:
  int col(double az) const { return std::clamp(static_cast<int>(az * per_rad_), 0, cols_ - 1); }
  int row(double el) const {
    return std::clamp(static_cast<int>(std::floor(el * per_rad_)), 0, rows_ - 1);
  }
  std::size_t offset(int c, int r) const {
    return static_cast<std::size_t>(r) * static_cast<std::size_t>(cols_) +
           static_cast<std::size_t>(c);
  }

  double per_rad_;
  int cols_, rows_;
  std::vector<float> range_;
};

// The surface normal at a point of the map from its neighbours within 1.5 voxels among `near`
// (the points of the map that may neighbour one asked about), for the points that ask. The
// neighbours are gathered from cells twice that wide, so that a point's ball meets at most
// two a side; each cell's points lie together, found through an open-addressing table
// (linear probing) of the cells' keys.
class SurfaceNormals {
 public:
  SurfaceNormals(const PointCloud& map, const std::vector<std::uint32_t>& near, double voxel_m)
      : map_(map),
        reach_(static_cast<float>(1.5 * voxel_m)),
        inv_cell_(1.0f / (2 * reach_)),
        slots_(std::bit_ceil(std::max<std::size_t>(2 * near.size(), 16)), {kEmpty, 0}),
        mask_(slots_.size() - 1) {
    // Each cell numbered as first met, its points counted, then laid out together.
    std::vector<std::uint32_t> cell_of(near.size());
    std::vector<std::uint32_t> count;
    for (std::size_t k = 0; k < near.size(); ++k) {
      const std::uint64_t key = key_of(cell_at(map.points[near[k]]));
      std::size_t at = hash(key);
      while (slots_[at].key != kEmpty && slots_[at].key != key) at = (at + 1) & mask_;
      if (slots_[at].key == kEmpty) {
        slots_[at] = {key, static_cast<std::uint32_t>(count.size())};
        count.push_back(0);
      }
      cell_of[k] = slots_[at].cell;
      ++count[slots_[at].cell];
    }
    begin_.assign(count.size() + 1, 0);
    for (std::size_t c = 0; c < count.size(); ++c) begin_[c + 1] = begin_[c] + count[c];
    points_.resize(near.size());
    std::vector<std::uint32_t> fill(begin_.begin(), begin_.end() - 1);
    for (std::size_t k = 0; k < near.size(); ++k) points_[fill[cell_of[k]]++] = map.points[near[k]];
  }

  // Zero where the neighbours make no plane (an edge, a post, a lone point).
  Eigen::Vector3f normal(std::size_t i) const {
    const Eigen::Vector3f& p = map_.points[i];
    const Eigen::Vector3i c0 = cell_at(p - Eigen::Vector3f::Constant(reach_));
    const float reach_sq = reach_ * reach_;
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    Eigen::Matrix3f outer = Eigen::Matrix3f::Zero();
    int n = 0;
    for (int dz = 0; dz <= 1; ++dz) {
      for (int dy = 0; dy <= 1; ++dy) {
        for (int dx = 0; dx <= 1; ++dx) {
          const std::uint64_t key = key_of(c0 + Eigen::Vector3i(dx, dy, dz));
          std::size_t at = hash(key);
          while (slots_[at].key != kEmpty && slots_[at].key != key) at = (at + 1) & mask_;
          if (slots_[at].key == kEmpty) continue;
          const std::uint32_t cell = slots_[at].cell;
          for (std::uint32_t k = begin_[cell]; k < begin_[cell + 1]; ++k) {
            const Eigen::Vector3f q = points_[k] - p;
            if (q.squaredNorm() > reach_sq) continue;
            sum += q;
            outer += q * q.transpose();
            ++n;
          }
        }
      }
    }
    if (n < kMinNeighbours) return Eigen::Vector3f::Zero();
    const Eigen::Vector3f mean = sum / static_cast<float>(n);
    const Eigen::Matrix3f cov = outer / static_cast<float>(n) - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3f> eig;
    eig.computeDirect(cov);
    const Eigen::Vector3f values = eig.eigenvalues();
    // Flat across, spread along two directions: a plane (not a line of points along a post or
    // an edge, whose two small spreads are noise).
    if (!(values(0) < kFlatness * values(1) && values(1) > kFlatness * values(2))) {
      return Eigen::Vector3f::Zero();
    }
    return eig.eigenvectors().col(0);
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  static constexpr int kMinNeighbours = 5;
  static constexpr float kFlatness = 0.1f;
  struct Slot {
    std::uint64_t key;
    std::uint32_t cell;
  };
  Eigen::Vector3i cell_at(const Eigen::Vector3f& p) const {
    return (p * inv_cell_).array().floor().cast<int>();
  }
  static std::uint64_t key_of(const Eigen::Vector3i& v) {
    const auto part = [](int c) { return static_cast<std::uint64_t>(c + (1 << 20)) & 0x1FFFFF; };
    return part(v.x()) | part(v.y()) << 21 | part(v.z()) << 42;
  }
  std::size_t hash(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> 20) & mask_;
  }

  const PointCloud& map_;
  float reach_, inv_cell_;
  std::vector<Slot> slots_;
  std::size_t mask_;
  std::vector<std::uint32_t> begin_;  // each cell's first point in points_, and one past the last
  std::vector<Eigen::Vector3f> points_;
};

}  // namespace

PointCloud visible_points(const PointCloud& map, const Eigen::Vector3f& eye, double voxel_m,
                          double max_range_m, const ViewCheckConfig& config,
                          const Viewpoints& views) {
  if (!(config.bin_deg > 0 && config.bin_deg <= 90)) {
    throw std::invalid_argument("view check: bin_deg must be within (0, 90] degrees, not " +
                                std::to_string(config.bin_deg));
  }
  RangeImage image(config.bin_deg);
  const auto max_range = static_cast<float>(max_range_m);
  // The scanner's own body and what it stands on right below it: no surface to match.
  constexpr float kMinRange = 0.5f;
  struct Seen {
    std::size_t bin;
    float range;
  };
  std::vector<Seen> seen(map.size(), {0, -1.0f});
  for (std::size_t i = 0; i < map.size(); ++i) {
    const Eigen::Vector3f d = map.points[i] - eye;
    const float range = d.norm();
    if (!(range >= kMinRange && range <= max_range)) continue;
    const RangeImage::Direction a = RangeImage::direction_of(d);
    seen[i] = {image.bin_of(a), range};
    // The voxel's half width, and a little more so that neighbouring voxels leave no gap.
    image.cover(a, std::atan(0.6 * voxel_m / range), range);
  }
  // Per bin, the nearest surface the scanner meets there: one return per beam, as a scan has;
  // a voxel spanning several bins (near the scanner) is still one point after the matcher's
  // thinning.
  constexpr auto kNone = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> first(image.size(), kNone);
  // The points on the surfaces met (a returned point's neighbours are among them).
  std::vector<std::uint32_t> front;
  for (std::size_t i = 0; i < map.size(); ++i) {
    const Seen& s = seen[i];
    if (s.range < 0) continue;
    const float hidden = std::max(static_cast<float>(config.hidden_m),
                                  static_cast<float>(config.hidden_share) * s.range);
    if (s.range > image.nearest(s.bin) + hidden) continue;
    front.push_back(static_cast<std::uint32_t>(i));
    std::uint32_t& f = first[s.bin];
    if (f == kNone || s.range < seen[f].range) f = static_cast<std::uint32_t>(i);
  }
  // A surface seen from its other side (the far face of a building, the back of a fence) is
  // solid: it hides what lies behind it, but returns nothing. Its points are in the map from
  // scans on that side; a part of the near face no scan has seen yet does not hide them, and
  // near a building's corner they made a facade look like a corner (issue 17: 0.10–0.16
  // predicted where the match met 0–0.014).
  const bool sided = views.fit(map.size());
  constexpr float kSameSideCos = 0.5f;
  // A surface its scanner saw edge-on (the far ground, 1.5 m below a sensor 60 m off: a cosine
  // of 0.025) has no side a normal a degree or two off could tell: kept.
  constexpr float kSideSeenCos = 0.15f;
  const auto back_face = static_cast<float>(config.back_face_cos);
  const std::optional<SurfaceNormals> normals =
      sided ? std::make_optional<SurfaceNormals>(map, front, voxel_m) : std::nullopt;
  PointCloud out;
  for (const std::uint32_t f : first) {
    if (f == kNone) continue;
    const Eigen::Vector3f& p = map.points[f];
    if (normals) {
      const Eigen::Vector3f to_eye = (eye - p).normalized();
      const Eigen::Vector3f to_view = (views.of(f) - p).normalized();
      // Looked at from within 60° of where it was seen from, a surface is seen from the same
      // side unless both look along it (a normal for every point would double the check's
      // cost).
      if (to_eye.dot(to_view) < kSameSideCos) {
        const Eigen::Vector3f n = normals->normal(f);
        const float facing_view = n.dot(to_view);
        // The normal turned toward the scanner that saw the point; the eye behind the surface.
        if (std::abs(facing_view) >= kSideSeenCos &&
            (facing_view < 0 ? -1.0f : 1.0f) * n.dot(to_eye) < -back_face)
          continue;
      }
    }
    out.points.push_back(p);
  }
  return out;
}

void check_views(Plan& plan, const std::function<double(const Candidate&)>& constraint,
                 const ViewCheckConfig& config, double floor_share) {
  if (!config.enabled) return;
  std::vector<Candidate>& ranked = plan.ranked;
  for (std::size_t checked = 0; checked < config.candidates && !ranked.empty(); ++checked) {
    Candidate& best = ranked.front();
    // No forecast (nothing anchored to match against), or checked already and still the best.
    if (!best.registrability || best.registrability->predicted_constraint) return;
    const double c = constraint(best);
    best.registrability->predicted_constraint = c;
    if (c >= config.min_constraint) return;
    const double s = c / config.min_constraint;
    const double keep = std::max(floor_share, s * s);
    best.registrability->factor *= keep;
    // A policy may rank by a negative score (a drive's cost): it falls either way.
    best.score -= (1 - keep) * std::abs(best.score);
    std::stable_sort(ranked.begin(), ranked.end(),
                     [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  }
}

}  // namespace scanplan

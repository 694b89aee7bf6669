#include "scanplan/mission/view_check.hpp"

#include <algorithm>
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

// The surface's normal at map point p from the judge's points within 1.5 voxels; zero where they
// make no plane: a line along a post or an edge has two small spreads, both noise.
Eigen::Vector3f plane_normal(const AlignmentJudge& judge, const Eigen::Vector3f& p,
                             double voxel_m) {
  constexpr double kFlatness = 0.1;
  const auto shape = judge.local_shape(p, 1.5 * voxel_m);
  if (!shape) return Eigen::Vector3f::Zero();
  const Eigen::Vector3d& s = shape->spread;
  if (!(s(0) < kFlatness * s(1) && s(1) > kFlatness * s(2))) return Eigen::Vector3f::Zero();
  return shape->normal.cast<float>();
}

}  // namespace

PointCloud visible_points(const PointCloud& map, const Eigen::Vector3f& eye, double voxel_m,
                          double max_range_m, const ViewCheckConfig& config,
                          const Viewpoints& views, const AlignmentJudge* judge) {
  if (!(config.bin_deg > 0 && config.bin_deg <= 90)) {
    throw std::invalid_argument("view check: bin_deg must be within (0, 90] degrees, not " +
                                std::to_string(config.bin_deg));
  }
  if (judge && &judge->target() != &map) {
    throw std::invalid_argument("view check: the judge must be one over the map's own points");
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
  for (std::size_t i = 0; i < map.size(); ++i) {
    const Seen& s = seen[i];
    if (s.range < 0) continue;
    const float hidden = std::max(static_cast<float>(config.hidden_m),
                                  static_cast<float>(config.hidden_share) * s.range);
    if (s.range > image.nearest(s.bin) + hidden) continue;
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
  std::optional<AlignmentJudge> own_judge;
  if (sided && !judge) judge = &own_judge.emplace(map);
  PointCloud out;
  for (const std::uint32_t f : first) {
    if (f == kNone) continue;
    const Eigen::Vector3f& p = map.points[f];
    if (sided) {
      const Eigen::Vector3f to_eye = (eye - p).normalized();
      const Eigen::Vector3f to_view = (views.of(f) - p).normalized();
      // Looked at from within 60° of where it was seen from, a surface is seen from the same
      // side unless both look along it (a normal for every point would double the check's
      // cost).
      if (to_eye.dot(to_view) < kSameSideCos) {
        const Eigen::Vector3f n = plane_normal(*judge, p, voxel_m);
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

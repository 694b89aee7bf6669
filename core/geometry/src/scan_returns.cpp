#include "scanplan/geometry/scan_returns.hpp"

#include <algorithm>
#include <vector>

namespace scanplan {

namespace {

// Whether p is a measurement at all: finite and within the scanner's reach of `sensor`.
bool in_reach(const Eigen::Vector3f& p, const Eigen::Vector3f& sensor, float max_range) {
  // In double: a float coordinate near 1e30 squares to infinity.
  return p.allFinite() && (p - sensor).cast<double>().norm() <= max_range;
}

struct Ranges {
  std::vector<float> range;  // from the sensor; 0 for points not in_reach
  float farthest = 0;
  bool shell = false;  // a saturation shell at `farthest`
};

Ranges ranges_from(const PointCloud& cloud, const Eigen::Vector3f& sensor,
                   const ReturnFilterConfig& config) {
  Ranges r;
  r.range.assign(cloud.size(), 0);
  const auto max_range = static_cast<float>(config.max_range_m);
  std::size_t finite = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!in_reach(cloud.points[i], sensor, max_range)) continue;
    r.range[i] = (cloud.points[i] - sensor).norm();
    r.farthest = std::max(r.farthest, r.range[i]);
    ++finite;
  }
  const auto band = static_cast<float>(config.saturation_band_m);
  std::size_t at_farthest = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    at_farthest += r.range[i] > 0 && r.range[i] >= r.farthest - band;
  }
  r.shell =
      at_farthest >= config.min_saturated_points &&
      static_cast<double>(at_farthest) >= config.min_saturated_share * static_cast<double>(finite);
  return r;
}

}  // namespace

Eigen::Vector3f locate_sensor(const PointCloud& cloud,
                              const std::vector<Eigen::Vector3f>& candidates,
                              const ReturnFilterConfig& config) {
  for (const auto& c : candidates) {
    if (ranges_from(cloud, c, config).shell) return c;
  }
  return candidates.empty() ? Eigen::Vector3f::Zero() : candidates.front();
}

DroppedReturns drop_bad_returns(PointCloud& cloud, const ReturnFilterConfig& config) {
  DroppedReturns dropped;
  const bool colored = cloud.has_colors();
  const Ranges r = ranges_from(cloud, config.sensor, config);
  const std::vector<float>& range = r.range;
  const float farthest = r.farthest;
  const bool shell = r.shell;
  const auto band = static_cast<float>(config.saturation_band_m);

  const auto mount = static_cast<float>(config.mount_radius_m);
  const auto max_range = static_cast<float>(config.max_range_m);
  std::size_t out = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) {
      ++dropped.non_finite;
    } else if (!in_reach(cloud.points[i], config.sensor, max_range)) {
      ++dropped.out_of_range;
    } else if (range[i] < mount) {
      ++dropped.mount;
    } else if (shell && range[i] >= farthest - band) {
      ++dropped.saturated;
    } else {
      cloud.points[out] = cloud.points[i];
      if (colored) cloud.colors[out] = cloud.colors[i];
      ++out;
    }
  }
  cloud.points.resize(out);
  if (colored) cloud.colors.resize(out);
  return dropped;
}

}  // namespace scanplan

#include "scanplan/geometry/scan_returns.hpp"

#include <algorithm>
#include <vector>

namespace scanplan {

DroppedReturns drop_bad_returns(PointCloud& cloud, const ReturnFilterConfig& config) {
  DroppedReturns dropped;
  const bool colored = cloud.has_colors();
  std::vector<float> range(cloud.size(), 0);
  float farthest = 0;
  std::size_t finite = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) continue;
    range[i] = cloud.points[i].norm();
    farthest = std::max(farthest, range[i]);
    ++finite;
  }
  const auto band = static_cast<float>(config.saturation_band_m);
  std::size_t at_farthest = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    at_farthest += cloud.points[i].allFinite() && range[i] >= farthest - band;
  }
  const bool shell =
      at_farthest >= config.min_saturated_points &&
      static_cast<double>(at_farthest) >= config.min_saturated_share * static_cast<double>(finite);

  const auto mount = static_cast<float>(config.mount_radius_m);
  std::size_t out = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!cloud.points[i].allFinite()) {
      ++dropped.non_finite;
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

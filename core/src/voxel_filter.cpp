#include "scanplan/core/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

namespace scanplan {
namespace {

constexpr std::int64_t kBias = std::int64_t{1} << 20;  // 21 bits a coordinate

bool voxel_key(const Eigen::Vector3f& p, double inv, std::uint64_t& key) {
  std::uint64_t k = 0;
  for (int a = 0; a < 3; ++a) {
    const double c = std::floor(p[a] * inv);
    if (!(c >= -kBias && c < kBias)) return false;  // also false for NaN
    k |= static_cast<std::uint64_t>(static_cast<std::int64_t>(c) + kBias) << (21 * a);
  }
  key = k;
  return true;
}

}  // namespace

PointCloud voxel_downsample(const PointCloud& cloud, double voxel_m) {
  PointCloud out;
  if (!(voxel_m > 0)) {
    out.points.reserve(cloud.size());
    for (const auto& p : cloud.points) {
      if (p.allFinite()) out.points.push_back(p);
    }
    return out;
  }
  const double inv = 1.0 / voxel_m;
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint64_t key;
    if (cloud.points[i].allFinite() && voxel_key(cloud.points[i], inv, key)) {
      keyed.emplace_back(key, static_cast<std::uint32_t>(i));
    }
  }
  std::sort(keyed.begin(), keyed.end());
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) {
      sum += cloud.points[keyed[end].second].cast<double>();
      ++end;
    }
    const Eigen::Vector3d centroid = sum / static_cast<double>(end - begin);
    std::size_t nearest = begin;
    double nearest_sq = std::numeric_limits<double>::max();
    for (std::size_t k = begin; k < end; ++k) {
      const double d = (cloud.points[keyed[k].second].cast<double>() - centroid).squaredNorm();
      if (d < nearest_sq) nearest_sq = d, nearest = k;
    }
    out.points.push_back(cloud.points[keyed[nearest].second]);
    begin = end;
  }
  return out;
}

}  // namespace scanplan

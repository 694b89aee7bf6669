#include "scanplan/geometry/voxel_filter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
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

// For each occupied voxel of side voxel_m > 0, its key and the index of the measured point
// nearest the centroid of the voxel's points; sorted by key.
std::vector<std::pair<std::uint64_t, std::uint32_t>> representatives(const PointCloud& cloud,
                                                                     double voxel_m) {
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
  std::vector<std::pair<std::uint64_t, std::uint32_t>> out;
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
    out.push_back(keyed[nearest]);
    begin = end;
  }
  return out;
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
  const auto reps = representatives(cloud, voxel_m);
  out.points.reserve(reps.size());
  for (const auto& [key, index] : reps) out.points.push_back(cloud.points[index]);
  return out;
}

VoxelMap::VoxelMap(double voxel_m) : voxel_m_(voxel_m) {
  if (!(voxel_m > 0) || !std::isfinite(voxel_m)) {
    throw std::invalid_argument("a voxel map needs a voxel size > 0 m, got " +
                                std::to_string(voxel_m));
  }
}

void VoxelMap::add(const PointCloud& cloud) {
  const auto reps = representatives(cloud, voxel_m_);
  if (reps.empty()) return;
  const bool colored = cloud.has_colors();
  // Both lists are sorted by key: one merge pass, linear in the map's size.
  std::vector<std::uint64_t> keys;
  PointCloud merged;
  keys.reserve(keys_.size() + reps.size());
  merged.reserve(keys_.size() + reps.size());
  std::size_t i = 0, j = 0;
  const auto take_new = [&] {
    const std::uint32_t k = reps[j].second;
    keys.push_back(reps[j].first);
    merged.push_back(cloud.points[k], colored ? cloud.colors[k] : kUncolored);
    ++j;
  };
  const auto take_old = [&] {
    keys.push_back(keys_[i]);
    merged.push_back(cloud_.points[i], cloud_.colors[i]);
    ++i;
  };
  while (i < keys_.size() || j < reps.size()) {
    if (j == reps.size() || (i < keys_.size() && keys_[i] < reps[j].first)) {
      take_old();
    } else if (i == keys_.size() || reps[j].first < keys_[i]) {
      take_new();
    } else {
      take_old();  // the voxel is known: its first point stays
      ++j;
    }
  }
  keys_ = std::move(keys);
  cloud_ = std::move(merged);
}

}  // namespace scanplan

#include "scanplan/geometry/voxel_filter.hpp"

#include <algorithm>
#include <array>
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

// `keyed` (keys of at most 63 bits, indices ascending) in the order std::sort gives the pairs:
// by key, then index. A least-significant-digit radix sort is stable, so entries of one key keep
// their ascending indices; 8 bits a pass, passes whose digit is the same for every key skipped
// (a scan's voxels share most of their high bits). Several times faster than a comparison sort
// on the hundreds of thousands of points of a whole scan.
void sort_by_key(std::vector<std::pair<std::uint64_t, std::uint32_t>>& keyed) {
  std::vector<std::pair<std::uint64_t, std::uint32_t>> spare(keyed.size());
  for (int shift = 0; shift < 64; shift += 8) {
    std::array<std::size_t, 257> start{};
    for (const auto& k : keyed) ++start[((k.first >> shift) & 0xff) + 1];
    if (std::any_of(start.begin() + 1, start.end(),
                    [&](std::size_t n) { return n == keyed.size(); })) {
      continue;  // one digit for all: nothing to reorder
    }
    for (std::size_t d = 1; d < start.size(); ++d) start[d] += start[d - 1];
    for (const auto& k : keyed) spare[start[(k.first >> shift) & 0xff]++] = k;
    keyed.swap(spare);
  }
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
  sort_by_key(keyed);
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

std::vector<std::uint32_t> voxel_kept(const PointCloud& cloud, double voxel_m) {
  std::vector<std::uint32_t> kept;
  if (!(voxel_m > 0)) {
    kept.reserve(cloud.size());
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      if (cloud.points[i].allFinite()) kept.push_back(static_cast<std::uint32_t>(i));
    }
    return kept;
  }
  const auto reps = representatives(cloud, voxel_m);
  kept.reserve(reps.size());
  for (const auto& [key, index] : reps) kept.push_back(index);
  return kept;
}

PointCloud picked(const PointCloud& cloud, const std::vector<std::uint32_t>& kept) {
  PointCloud out;
  out.points.reserve(kept.size());
  for (const std::uint32_t i : kept) out.points.push_back(cloud.points[i]);
  if (cloud.has_colors()) {
    out.colors.reserve(kept.size());
    for (const std::uint32_t i : kept) out.colors.push_back(cloud.colors[i]);
  }
  return out;
}

PointCloud voxel_downsample(const PointCloud& cloud, double voxel_m) {
  const std::vector<std::uint32_t> kept = voxel_kept(cloud, voxel_m);
  PointCloud out;
  out.points.reserve(kept.size());
  for (const std::uint32_t i : kept) out.points.push_back(cloud.points[i]);
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

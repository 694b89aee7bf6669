#include "scanplan/geometry/voxel_filter.hpp"

#include <algorithm>
#include <array>
#include <bit>
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
// on the hundreds of thousands of voxels of a whole map.
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

// The voxels of a cloud, numbered in the order their first point comes: an open-addressing
// table from key to number, grown by doubling. A map's points near a new scan are millions
// (issue 19), in some hundred thousand voxels: looking each up in a table that fits the cache
// is several times faster than sorting every point by its voxel.
class VoxelNumbers {
 public:
  // The voxel's number, a new one if the key is new.
  std::uint32_t number(std::uint64_t key) {
    if (2 * (keys_.size() + 1) > slots_.size()) grow();
    for (std::size_t s = slot(key);; s = (s + 1) & mask_) {
      if (slots_[s] == kEmpty) {
        slots_[s] = static_cast<std::uint32_t>(keys_.size());
        keys_.push_back(key);
        return slots_[s];
      }
      if (keys_[slots_[s]] == key) return slots_[s];
    }
  }
  const std::vector<std::uint64_t>& keys() const { return keys_; }

 private:
  static constexpr std::uint32_t kEmpty = std::numeric_limits<std::uint32_t>::max();
  std::size_t slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void grow() {
    const std::size_t size = slots_.empty() ? 1024 : 2 * slots_.size();
    slots_.assign(size, kEmpty);
    mask_ = size - 1;
    shift_ = 64 - std::countr_zero(size);
    for (std::uint32_t n = 0; n < keys_.size(); ++n) {
      std::size_t s = slot(keys_[n]);
      while (slots_[s] != kEmpty) s = (s + 1) & mask_;
      slots_[s] = n;
    }
  }
  std::vector<std::uint32_t> slots_;
  std::vector<std::uint64_t> keys_;  // by number
  std::size_t mask_ = 0;
  int shift_ = 64;
};

// For each occupied voxel of side voxel_m > 0, its key and the index of the measured point
// nearest the centroid of the voxel's points (the first of equals); sorted by key. Points are
// summed and compared in index order, so the result does not depend on the table.
std::vector<std::pair<std::uint64_t, std::uint32_t>> representatives(const PointCloud& cloud,
                                                                     double voxel_m) {
  constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
  const double inv = 1.0 / voxel_m;
  VoxelNumbers numbers;
  std::vector<std::uint32_t> number_of(cloud.size(), kNone);
  std::vector<Eigen::Vector3d> centroids;  // the sums until divided
  std::vector<std::uint32_t> counts;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    std::uint64_t key;
    if (!cloud.points[i].allFinite() || !voxel_key(cloud.points[i], inv, key)) continue;
    const std::uint32_t n = numbers.number(key);
    if (n == centroids.size()) {
      centroids.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    centroids[n] += cloud.points[i].cast<double>();
    ++counts[n];
    number_of[i] = n;
  }
  for (std::size_t n = 0; n < centroids.size(); ++n) centroids[n] /= static_cast<double>(counts[n]);
  std::vector<std::uint32_t> nearest(centroids.size(), kNone);
  std::vector<double> nearest_sq(centroids.size(), std::numeric_limits<double>::max());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::uint32_t n = number_of[i];
    if (n == kNone) continue;
    const double d = (cloud.points[i].cast<double>() - centroids[n]).squaredNorm();
    if (d < nearest_sq[n]) nearest_sq[n] = d, nearest[n] = static_cast<std::uint32_t>(i);
  }
  std::vector<std::pair<std::uint64_t, std::uint32_t>> out;
  out.reserve(nearest.size());
  for (std::size_t n = 0; n < nearest.size(); ++n) out.emplace_back(numbers.keys()[n], nearest[n]);
  sort_by_key(out);
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

#include "scanplan/registration/ndt_grid.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace scanplan {
namespace {

constexpr std::int64_t kBias = std::int64_t{1} << 20;  // 21 bits a coordinate

std::uint64_t pack(std::int64_t x, std::int64_t y, std::int64_t z) {
  return static_cast<std::uint64_t>(x + kBias) | static_cast<std::uint64_t>(y + kBias) << 21 |
         static_cast<std::uint64_t>(z + kBias) << 42;
}

bool in_range(std::int64_t c) {
  return c >= -kBias && c < kBias;
}

std::uint64_t slot_hash(std::uint64_t key) {
  return key * 0x9E3779B97F4A7C15ull;  // Fibonacci hashing spreads neighbouring keys
}

}  // namespace

NdtGrid::NdtGrid(const std::vector<Eigen::Vector3f>& points, double cell_m,
                 const NdtGridOptions& options)
    : cell_m_(cell_m), inv_cell_(1.0 / cell_m) {
  if (!(cell_m > 0)) throw std::invalid_argument("NDT cell size must be positive");
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed;
  keyed.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    std::int64_t c[3];
    if (key_of(points[i].cast<double>(), c)) {
      keyed.emplace_back(pack(c[0], c[1], c[2]), static_cast<std::uint32_t>(i));
    }
  }
  std::sort(keyed.begin(), keyed.end());

  std::vector<std::uint64_t> keys;
  for (std::size_t begin = 0; begin < keyed.size();) {
    std::size_t end = begin;
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) ++end;
    if (static_cast<int>(end - begin) >= options.min_points_per_cell) {
      // Moments about the first point: a 20 m cell far from the origin would otherwise lose
      // the covariance to cancellation in Σxxᵀ − n·μμᵀ.
      const Eigen::Vector3d origin = points[keyed[begin].second].cast<double>();
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      for (std::size_t k = begin; k < end; ++k) {
        const Eigen::Vector3d d = points[keyed[k].second].cast<double>() - origin;
        sum += d;
        outer += d * d.transpose();
      }
      const double n = static_cast<double>(end - begin);
      const Eigen::Vector3d mean = sum / n;
      const Eigen::Matrix3d cov = (outer - n * mean * mean.transpose()) / (n - 1);
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
      Eigen::Vector3d lambda = eig.eigenvalues();
      const double floor_value = std::max(lambda.maxCoeff() * options.min_eigenvalue_ratio, 1e-12);
      if (lambda.maxCoeff() > 0) {
        lambda = lambda.cwiseMax(floor_value);
        NdtCell cell;
        cell.mean = origin + mean;
        cell.inverse_covariance = eig.eigenvectors() * lambda.cwiseInverse().asDiagonal() *
                                  eig.eigenvectors().transpose();
        cell.count = static_cast<std::uint32_t>(end - begin);
        cells_.push_back(cell);
        keys.push_back(keyed[begin].first);
      }
    }
    begin = end;
  }

  const std::size_t capacity = std::bit_ceil(std::max<std::size_t>(16, 2 * cells_.size()));
  slot_mask_ = capacity - 1;
  slot_keys_.assign(capacity, 0);
  slot_cells_.assign(capacity, -1);
  for (std::size_t i = 0; i < keys.size(); ++i) {
    std::uint64_t s = slot_hash(keys[i]) >> 20 & slot_mask_;
    while (slot_cells_[s] >= 0) s = (s + 1) & slot_mask_;
    slot_keys_[s] = keys[i];
    slot_cells_[s] = static_cast<std::int32_t>(i);
  }
}

bool NdtGrid::key_of(const Eigen::Vector3d& p, std::int64_t (&c)[3]) const {
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor(p[a] * inv_cell_);
    if (!(f >= -kBias && f < kBias)) return false;
    c[a] = static_cast<std::int64_t>(f);
  }
  return true;
}

const NdtCell* NdtGrid::find(std::int64_t x, std::int64_t y, std::int64_t z) const {
  if (!in_range(x) || !in_range(y) || !in_range(z)) return nullptr;
  return find_key(pack(x, y, z));
}

const NdtCell* NdtGrid::find_key(std::uint64_t key) const {
  for (std::uint64_t s = slot_hash(key) >> 20 & slot_mask_;; s = (s + 1) & slot_mask_) {
    const std::int32_t c = slot_cells_[s];
    if (c < 0) return nullptr;
    if (slot_keys_[s] == key) return &cells_[static_cast<std::size_t>(c)];
  }
}

const NdtCell* NdtGrid::cell_at(const Eigen::Vector3d& p) const {
  std::int64_t c[3];
  return key_of(p, c) ? find(c[0], c[1], c[2]) : nullptr;
}

bool NdtGrid::block_of(const Eigen::Vector3d& p, std::uint64_t& key,
                       Eigen::Vector3d& fraction) const {
  // Shifting by half a cell makes floor() give the lower corner of the 2×2×2 block whose
  // centres surround p.
  const Eigen::Vector3d shifted = p - Eigen::Vector3d::Constant(0.5 * cell_m_);
  std::int64_t c[3];
  if (!key_of(shifted, c)) return false;
  for (int a = 0; a < 3; ++a) {
    if (!in_range(c[a] + 1)) return false;  // the block's far corner must pack too
    fraction[a] = shifted[a] * inv_cell_ - static_cast<double>(c[a]);
  }
  key = pack(c[0], c[1], c[2]);
  return true;
}

void NdtGrid::block_cells(std::uint64_t key, std::array<const NdtCell*, 8>& out) const {
  // Packing is linear in each coordinate, so the neighbours' keys are offsets of the corner's.
  constexpr std::uint64_t kY = std::uint64_t{1} << 21, kZ = std::uint64_t{1} << 42;
  for (int k = 0; k < 8; ++k) {
    out[k] = find_key(key + (k & 1) + ((k >> 1) & 1) * kY + ((k >> 2) & 1) * kZ);
  }
}

int NdtGrid::neighbourhood(const Eigen::Vector3d& p, std::array<const NdtCell*, 8>& out,
                           std::array<double, 8>& weight) const {
  std::uint64_t key;
  Eigen::Vector3d f;
  if (!block_of(p, key, f)) return 0;
  std::array<const NdtCell*, 8> block;
  block_cells(key, block);
  int n = 0;
  for (int k = 0; k < 8; ++k) {
    if (!block[k]) continue;
    weight[n] =
        (k & 1 ? f.x() : 1 - f.x()) * (k & 2 ? f.y() : 1 - f.y()) * (k & 4 ? f.z() : 1 - f.z());
    out[n++] = block[k];
  }
  return n;
}

}  // namespace scanplan

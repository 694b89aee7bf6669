#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <vector>

namespace scanplan {

// The normal distribution of the target points in one cell (paper §4.2: mean q_i, covariance
// Σ_i), kept as its inverse since the score only ever needs Σ⁻¹.
struct NdtCell {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Matrix3d inverse_covariance = Eigen::Matrix3d::Identity();
  std::uint32_t count = 0;
};

struct NdtGridOptions {
  // Fewer points than this give no usable covariance; such cells are left out.
  int min_points_per_cell = 6;
  // Points on a plane or a line make Σ singular; eigenvalues below this share of the largest
  // are raised to it (Magnusson 2009 §6.2 uses 0.001–0.01) so that Σ⁻¹ stays bounded.
  double min_eigenvalue_ratio = 0.01;
};

// The NDT of a point set: a hash of the cubic cells of side `cell_m` that hold enough points,
// each with its Gaussian. Lookups go through an open-addressing table because the optimiser
// queries eight cells per point per evaluation, millions of times per match.
class NdtGrid {
 public:
  NdtGrid(const std::vector<Eigen::Vector3f>& points, double cell_m,
          const NdtGridOptions& options = {});

  double cell_m() const { return cell_m_; }
  std::size_t size() const { return cells_.size(); }
  const std::vector<NdtCell>& cells() const { return cells_; }

  // The cell containing p, or null.
  const NdtCell* cell_at(const Eigen::Vector3d& p) const;

  // The cells of the 2×2×2 block whose centres are nearest p — the cells trilinear
  // interpolation would blend (Magnusson 2009 §6.2.4) — that have a Gaussian. Summing over them
  // smooths the score across cell borders, which a single cell per point would make jump.
  // Returns how many were written to `out`; `weight` gets each one's trilinear weight (the
  // eight weights of a full block sum to 1).
  int neighbourhood(const Eigen::Vector3d& p, std::array<const NdtCell*, 8>& out,
                    std::array<double, 8>& weight) const;

  // The same in two steps, for callers that cache the lookups: the block around p (its key and
  // p's position inside it, each coordinate in [0, 1)), and the cells of a block (null where a
  // cell has no Gaussian), in the order z, y, x with x fastest. block_of is false out of range.
  bool block_of(const Eigen::Vector3d& p, std::uint64_t& key, Eigen::Vector3d& fraction) const;
  void block_cells(std::uint64_t key, std::array<const NdtCell*, 8>& out) const;

 private:
  bool key_of(const Eigen::Vector3d& p, std::int64_t (&c)[3]) const;
  const NdtCell* find(std::int64_t x, std::int64_t y, std::int64_t z) const;
  const NdtCell* find_key(std::uint64_t key) const;

  double cell_m_;
  double inv_cell_;
  std::vector<NdtCell> cells_;
  // Open addressing, linear probing: slot keys and the index of their cell (or -1 when empty).
  std::vector<std::uint64_t> slot_keys_;
  std::vector<std::int32_t> slot_cells_;
  std::uint64_t slot_mask_ = 0;
};

}  // namespace scanplan

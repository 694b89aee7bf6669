#include "scanplan/registration/narrower_ndt.hpp"

#ifdef _OPENMP
#include <omp.h>
#endif

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>

#include "pose_increment.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/geometry/voxel_filter.hpp"

namespace scanplan {
namespace {

using detail::Mat;
using detail::metres;
using detail::Vec;

// The constants of the Gaussian score (Magnusson 2009 eq. 6.8): a mixture of a normal
// distribution and a uniform outlier density, fitted by a Gaussian d1·exp(−d2·m/2).
struct ScoreShape {
  double d1, d2;
  ScoreShape(double outlier_ratio, double cell_m) {
    const double c1 = 10.0 * (1.0 - outlier_ratio);
    const double c2 = outlier_ratio / (cell_m * cell_m * cell_m);
    const double d3 = -std::log(c2);
    d1 = -std::log(c1 + c2) - d3;
    d2 = -2.0 * std::log((-std::log(c1 * std::exp(-0.5) + c2) - d3) / d1);
  }
};

template <int N>
struct Derivatives {
  double cost = 0;  // Σ d1·exp(−d2·m/2); d1 < 0, so lower is better
  Vec<N> gradient = Vec<N>::Zero();
  Mat<N> hessian = Mat<N>::Zero();
  int matched = 0;  // points with at least one Gaussian around them

  void add(const Derivatives& o) {
    cost += o.cost;
    gradient += o.gradient;
    hessian += o.hessian;
    matched += o.matched;
  }
};

// Past this Mahalanobis distance a term is below e^-15 of its peak: not worth the work.
constexpr double kMaxExponent = 30.0;

// The NDT score of a source point set against a grid, with its derivatives.
template <int N>
class NdtProblem {
 public:
  NdtProblem(const NdtGrid& grid, const std::vector<Eigen::Vector3d>& source, ScoreShape shape,
             int threads)
      : grid_(grid), source_(source), shape_(shape), threads_(threads), blocks_(source.size()) {}

  // Not thread-safe: each point's block lookup is cached between calls, since from one
  // evaluation to the next a point rarely leaves its 2×2×2 block.
  template <bool kDerivatives>
  Derivatives<N> evaluate(const Eigen::Isometry3d& T) const {
    Derivatives<N> total;
    const int n = static_cast<int>(source_.size());
#pragma omp parallel num_threads(threads_)
    {
      Derivatives<N> local;
#pragma omp for schedule(static) nowait
      for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d p = T * source_[i];
        std::uint64_t key;
        Eigen::Vector3d f;
        if (!grid_.block_of(p, key, f)) continue;
        CachedBlock& block = blocks_[static_cast<std::size_t>(i)];
        if (block.key != key) {
          block.key = key;
          grid_.block_cells(key, block.cells);
        }
        bool matched = false;
        [[maybe_unused]] Eigen::Matrix<double, 3, N> J;
        if constexpr (kDerivatives) J = detail::point_jacobian<N>(p);
        for (int c = 0; c < 8; ++c) {
          const NdtCell* cell = block.cells[c];
          if (!cell) continue;
          matched = true;
          // Trilinear weights: each point weighs one Gaussian's worth wherever it is. A plain
          // sum over the block would pay points for sitting where more cells exist, pulling the
          // source towards the middle of the target's coverage (metres, on the campus).
          // The weights are held constant in the derivatives, as Magnusson does.
          const double weight = (c & 1 ? f.x() : 1 - f.x()) * (c & 2 ? f.y() : 1 - f.y()) *
                                (c & 4 ? f.z() : 1 - f.z());
          const Eigen::Vector3d q = p - cell->mean;
          const Eigen::Vector3d w = cell->inverse_covariance * q;
          const double exponent = 0.5 * shape_.d2 * q.dot(w);
          if (exponent > kMaxExponent) continue;
          const double e = std::exp(-exponent) * weight;
          local.cost += shape_.d1 * e;
          if constexpr (kDerivatives) {
            // d(cost)/dθ = −d1·d2·e·(wᵀJ); the Hessian adds the curvature of the Mahalanobis
            // term (JᵀΣ⁻¹J), of the exponential (−d2·aᵀa) and of the rotation (wᵀ·d²p/dθ²).
            const double k = -shape_.d1 * shape_.d2 * e;
            const Eigen::Matrix<double, 1, N> a = w.transpose() * J;
            local.gradient += k * a.transpose();
            Mat<N> h = J.transpose() * cell->inverse_covariance * J - shape_.d2 * a.transpose() * a;
            h.template bottomRightCorner<N - 3, N - 3>() +=
                detail::contracted_point_hessian<N>(p, w);
            local.hessian += k * h;
          }
        }
        local.matched += matched;
      }
#pragma omp critical
      total.add(local);
    }
    return total;
  }

 private:
  struct CachedBlock {
    std::uint64_t key = ~std::uint64_t{0};
    std::array<const NdtCell*, 8> cells{};
  };
  const NdtGrid& grid_;
  const std::vector<Eigen::Vector3d>& source_;
  ScoreShape shape_;
  int threads_;
  mutable std::vector<CachedBlock> blocks_;
};

// A descent direction from the Newton system: eigenvalues replaced by their magnitude (and kept
// off zero), so that where the score is not convex the step still goes downhill.
template <int N>
Vec<N> newton_direction(const Mat<N>& H, const Vec<N>& g) {
  Eigen::SelfAdjointEigenSolver<Mat<N>> eig(H);
  Vec<N> lambda = eig.eigenvalues().cwiseAbs();
  const double floor_value = std::max(lambda.maxCoeff() * 1e-6, 1e-12);
  lambda = lambda.cwiseMax(floor_value);
  return -(eig.eigenvectors() * (eig.eigenvectors().transpose() * g).cwiseQuotient(lambda));
}

template <int N>
Vec<N> clamp_step(Vec<N> step, double max_translation, double max_rotation) {
  const auto [t, r] = detail::step_size<N>(step);
  double scale = 1.0;
  if (t > max_translation) scale = std::min(scale, max_translation / t);
  if (r > max_rotation) scale = std::min(scale, max_rotation / r);
  return step * scale;
}

struct LevelOutcome {
  int iterations = 0;
  bool converged = false;
  double cost = 0;      // at the final transform
  std::string failure;  // empty unless the level could not run
};

template <int N>
LevelOutcome optimise_level(const NdtProblem<N>& problem, double cell_m, std::size_t points,
                            const NdtConfig& config, Eigen::Isometry3d& T) {
  LevelOutcome out;
  const std::size_t min_matched = static_cast<std::size_t>(std::max(config.min_matched_points, 1));
  Derivatives<N> d = problem.template evaluate<true>(T);
  for (; out.iterations < config.max_iterations; ++out.iterations) {
    if (static_cast<std::size_t>(d.matched) < min_matched) {
      out.failure = "only " + std::to_string(d.matched) + " of " + std::to_string(points) +
                    " source points lie near a target Gaussian at cell size " + metres(cell_m) +
                    ": the clouds do not overlap from this start";
      return out;
    }
    const Vec<N> step = clamp_step<N>(newton_direction<N>(d.hessian, d.gradient),
                                      cell_m * config.max_step_per_cell, config.max_step_rad);
    const double slope = d.gradient.dot(step);
    if (!(slope < 0)) {  // already at a stationary point
      out.converged = true;
      out.cost = d.cost;
      return out;
    }
    // Backtracking with the Armijo condition: accept the longest of 1, ½, ¼, ... that lowers
    // the cost by a fair share of what the slope promises.
    // The first trial is evaluated with derivatives: it is accepted most of the time, and then
    // they are the next iteration's.
    double alpha = 1.0;
    Eigen::Isometry3d candidate = detail::apply_increment<N>(T, step);
    Derivatives<N> next = problem.template evaluate<true>(candidate);
    bool accepted = next.cost <= d.cost + 1e-4 * slope;
    for (int halving = 1; !accepted && halving < 12; ++halving) {
      alpha *= 0.5;
      candidate = detail::apply_increment<N>(T, alpha * step);
      accepted = problem.template evaluate<false>(candidate).cost <= d.cost + 1e-4 * alpha * slope;
      if (accepted) next = problem.template evaluate<true>(candidate);
    }
    const auto [moved, turned] = detail::step_size<N>(Vec<N>(alpha * step));
    const bool small = moved < cell_m * config.translation_tolerance_per_cell &&
                       turned < config.rotation_tolerance_rad;
    if (!accepted || small) {
      if (accepted) T = candidate;
      out.cost = accepted ? next.cost : d.cost;
      // No downhill step this short exists: we are at the minimum to within the tolerances.
      out.converged = true;
      ++out.iterations;
      return out;
    }
    T = candidate;
    d = next;
  }
  out.cost = d.cost;
  return out;
}

// The starts tried at the first cell size, best first: every yaw offset × every grid shift,
// ranked by the NDT cost on a sparse copy of the source, the best `search_keep` kept. With no
// translation search and few yaw offsets, all of them (no ranking needed).
template <int N>
std::vector<Eigen::Isometry3d> hypotheses(const NdtGrid& grid, const PointCloud& source,
                                          const Eigen::Isometry3d& start, double cell,
                                          const NdtConfig& config, int threads) {
  std::vector<double> yaws = config.yaw_hypotheses_deg;
  if (yaws.empty()) yaws = {0.0};
  const int k = std::max(config.translation_search_steps, 0);
  const double step = cell * config.translation_search_step_per_cell;
  std::vector<Eigen::Isometry3d> all;
  for (const double yaw : yaws) {
    for (int ix = -k; ix <= k; ++ix) {
      for (int iy = -k; iy <= k; ++iy) {
        Eigen::Isometry3d T = start;
        T.linear() = Eigen::AngleAxisd(deg2rad(yaw), Eigen::Vector3d::UnitZ()) * start.linear();
        T.translation() += Eigen::Vector3d(ix * step, iy * step, 0);
        all.push_back(T);
      }
    }
  }
  const std::size_t keep = static_cast<std::size_t>(std::max(config.search_keep, 1));
  if (all.size() <= keep) return all;
  const PointCloud sparse = voxel_downsample(source, cell * config.search_voxel_per_cell);
  std::vector<Eigen::Vector3d> points;
  for (const auto& p : sparse.points) points.push_back(p.cast<double>());
  const NdtProblem<N> screen(grid, points, ScoreShape(config.outlier_ratio, cell), threads);
  std::vector<std::pair<double, std::size_t>> ranked;
  for (std::size_t i = 0; i < all.size(); ++i) {
    ranked.emplace_back(screen.template evaluate<false>(all[i]).cost, i);
  }
  std::partial_sort(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(keep),
                    ranked.end());
  std::vector<Eigen::Isometry3d> best;
  for (std::size_t i = 0; i < keep; ++i) best.push_back(all[ranked[i].second]);
  return best;
}

template <int N>
RegistrationResult align(const PointCloud& target, const PointCloud& source,
                         const Eigen::Isometry3d& initial, const NdtConfig& config) {
  RegistrationResult result;
  result.method = "ndt";
  result.transform = initial;
  if (config.cell_sizes_m.empty()) {
    result.message = "no NDT cell sizes configured";
    return result;
  }
#ifdef _OPENMP
  const int threads = config.num_threads > 0 ? config.num_threads : omp_get_max_threads();
#else
  const int threads = config.num_threads > 0 ? config.num_threads : 1;
#endif
  for (std::size_t level = 0; level < config.cell_sizes_m.size(); ++level) {
    const double cell = config.cell_sizes_m[level];
    if (!(cell > 0)) {
      result.message = "NDT cell sizes must be positive";
      return result;
    }
    const NdtGrid grid(target.points, cell, config.grid);
    if (grid.size() == 0) {
      result.message = "the target has no cell of " + metres(cell) + " with " +
                       std::to_string(config.grid.min_points_per_cell) + " points or more";
      return result;
    }
    const PointCloud thinned = voxel_downsample(source, cell * config.source_voxel_per_cell);
    std::vector<Eigen::Vector3d> points;
    points.reserve(thinned.size());
    for (const auto& p : thinned.points) points.push_back(p.cast<double>());
    const NdtProblem<N> problem(grid, points, ScoreShape(config.outlier_ratio, cell), threads);
    // At the first cell size the match also starts from hypotheses around the initial guess:
    // turned by the yaw offsets about the source's origin and, when a translation search is
    // configured, shifted on a grid; a cheap score on a sparse source ranks them and the best
    // few are optimised. The one that ends at the lowest cost goes on.
    const Eigen::Isometry3d start = result.transform;
    std::vector<Eigen::Isometry3d> starts;
    if (level == 0) {
      starts = hypotheses<N>(grid, source, start, cell, config, threads);
    } else {
      starts = {start};
    }
    // Each hypothesis gets a few steps only; the best of them then runs to convergence.
    NdtConfig trial_config = config;
    if (starts.size() > 1) trial_config.max_iterations = config.hypothesis_iterations;
    LevelOutcome outcome;
    for (std::size_t h = 0; h < starts.size(); ++h) {
      Eigen::Isometry3d T = starts[h];
      const LevelOutcome trial = optimise_level<N>(problem, cell, points.size(), trial_config, T);
      result.iterations += trial.iterations;
      const bool better =
          trial.failure.empty() && (!outcome.failure.empty() || trial.cost < outcome.cost);
      if (h == 0 || better) {
        outcome = trial;
        result.transform = T;
      }
    }
    if (starts.size() > 1 && outcome.failure.empty() && !outcome.converged) {
      outcome = optimise_level<N>(problem, cell, points.size(), config, result.transform);
      result.iterations += outcome.iterations;
    }
    if (!outcome.failure.empty()) {
      result.message = outcome.failure;
      return result;
    }
    // Only the finest cell size decides: the coarse ones are there to bring it into range.
    result.converged = outcome.converged;
    if (!outcome.converged && level + 1 == config.cell_sizes_m.size()) {
      result.ran_out = true;
      result.message = "NDT did not settle within " + std::to_string(config.max_iterations) +
                       " iterations at cell size " + metres(cell);
    }
  }
  return result;
}

}  // namespace

RegistrationResult align_narrower_ndt(const PointCloud& target, const PointCloud& source,
                                      const Eigen::Isometry3d& initial, Dof dof,
                                      const NdtConfig& config) {
  return detail::with_dof(dof, [&]<int N>() { return align<N>(target, source, initial, config); });
}

}  // namespace scanplan

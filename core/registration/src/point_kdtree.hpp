#pragma once

// Nearest-neighbour search over a fixed set of points (nanoflann), for the ICP correspondences
// and the Eq. 2 score. Private to the library so that nanoflann stays out of public headers.

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cstdint>
#include <limits>
#include <memory>
#include <nanoflann.hpp>
#include <vector>

namespace scanplan::detail {

class PointKdTree {
 public:
  // Keeps a reference to `points`, which must outlive the tree and not change.
  explicit PointKdTree(const std::vector<Eigen::Vector3f>& points)
      : adaptor_{&points},
        index_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(/*leaf_max_size=*/16)) {}

  std::size_t size() const { return adaptor_.points->size(); }
  const Eigen::Vector3f& point(std::uint32_t i) const { return (*adaptor_.points)[i]; }

  // The up to `K` nearest points closer than sqrt(max_sq), nearest first; returns how many.
  // Bounding the search by max_sq lets queries far from everything stop early.
  template <int K>
  int nearest(const Eigen::Vector3f& q, float max_sq, std::uint32_t (&index)[K],
              float (&sq)[K]) const {
    if (size() == 0) return 0;
    nanoflann::KNNResultSet<float, std::uint32_t> result(K);
    result.init(index, sq);
    sq[K - 1] = max_sq;  // the search only keeps points nearer than the current worst
    index_.findNeighbors(result, q.data(), nanoflann::SearchParams());
    return static_cast<int>(result.size());
  }

  // The shape of the surface around q: the eigen-decomposition (eigenvalues ascending) of the
  // scatter of its up to K nearest points within sqrt(max_sq); false with fewer than 5 of them.
  template <int K>
  bool local_shape(const Eigen::Vector3f& q, float max_sq,
                   Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>& eig) const {
    std::uint32_t index[K];
    float sq[K];
    const int found = nearest<K>(q, max_sq, index, sq);
    if (found < 5) return false;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int k = 0; k < found; ++k) {
      const Eigen::Vector3f& p = point(index[k]);
      mean += p.cast<double>();
    }
    mean /= found;
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    for (int k = 0; k < found; ++k) {
      const Eigen::Vector3f& p = point(index[k]);
      const Eigen::Vector3d d = p.cast<double>() - mean;
      scatter += d * d.transpose();
    }
    eig.computeDirect(scatter);
    return true;
  }

 private:
  struct Adaptor {
    const std::vector<Eigen::Vector3f>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    float kdtree_get_pt(std::size_t i, std::size_t dim) const { return (*points)[i][dim]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Index = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, Adaptor>,
                                                    Adaptor, 3, std::uint32_t>;
  Adaptor adaptor_;
  Index index_;
};

}  // namespace scanplan::detail

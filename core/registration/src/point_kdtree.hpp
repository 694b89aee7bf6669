#pragma once

// Nearest-neighbour search over a fixed set of points (nanoflann), for the ICP correspondences
// and the Eq. 2 score. Private to the library so that nanoflann stays out of public headers.

#include <Eigen/Core>
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

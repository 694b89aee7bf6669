#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

namespace scanplan {

// Where the scanner stood when it measured each point of a cloud, in the cloud's frame. A
// surface's normal turned toward the scanner that saw it tells the two faces of a thin wall, a
// post or a trunk apart, which matching needs when two scans see such a thing from opposite
// sides: on the campus, GICP pulled scans 39 m apart on either side of a 10 cm fence 8–15 cm
// toward each other, and the scans matched to them later inherited the offset (issue 17).
struct Viewpoints {
  std::vector<Eigen::Vector3f> origins;  // none: not known
  // Per point, its index into `origins`; empty when every point was seen from origins[0].
  std::vector<std::uint32_t> origin_of;

  static Viewpoints single(const Eigen::Vector3f& origin) { return {{origin}, {}}; }
  bool known() const { return !origins.empty(); }
  // Whether these describe a cloud of `points` points: known, and one valid index a point
  // unless there is a single origin.
  bool fit(std::size_t points) const;
  const Eigen::Vector3f& of(std::size_t point) const {
    return origin_of.empty() ? origins.front() : origins[origin_of[point]];
  }
  // The viewpoints of the points `kept` (indices into the cloud these describe), in that order:
  // for a cloud thinned or cropped to those points.
  Viewpoints picked(const std::vector<std::uint32_t>& kept) const;
  // For the cloud moved by `t`.
  Viewpoints transformed(const Eigen::Isometry3f& t) const;
};

// The viewpoints of the two clouds of a match; either unknown and matching does without.
struct MatchViews {
  Viewpoints target, source;
};

}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <limits>
#include <vector>

namespace scanplan {

using Rgb = std::array<std::uint8_t, 3>;

// Points and their colours kept in two parallel arrays: the geometry code
// (matching, MLS insertion) touches only `points`, so colour stays out of its cache lines.
struct PointCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<Rgb> colors;  // empty or one per point

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_colors() const { return !colors.empty() && colors.size() == points.size(); }
  void reserve(std::size_t n) {
    points.reserve(n);
    colors.reserve(n);
  }
  void push_back(const Eigen::Vector3f& p, const Rgb& c) {
    points.push_back(p);
    colors.push_back(c);
  }
  void append(const PointCloud& other);
};

struct Bounds3 {
  Eigen::Vector3f min{Eigen::Vector3f::Constant(std::numeric_limits<float>::max())};
  Eigen::Vector3f max{Eigen::Vector3f::Constant(std::numeric_limits<float>::lowest())};
  bool valid() const { return (min.array() <= max.array()).all(); }
  void extend(const Eigen::Vector3f& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
};

Bounds3 bounds_of(const PointCloud& cloud);

}  // namespace scanplan

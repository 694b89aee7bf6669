#pragma once

#include <Eigen/Core>
#include <vector>

namespace scanplan::test {

// A square of points filling cells [x0, x1) × [y0, y1) at height z, `per_cell` per 1 m cell.
inline std::vector<Eigen::Vector3f> slab(int x0, int x1, int y0, int y1, float z,
                                         int per_cell = 4) {
  std::vector<Eigen::Vector3f> pts;
  for (int x = x0; x < x1; ++x) {
    for (int y = y0; y < y1; ++y) {
      for (int k = 0; k < per_cell; ++k) {
        pts.emplace_back(static_cast<float>(x) + 0.2f + 0.15f * static_cast<float>(k),
                         static_cast<float>(y) + 0.3f + 0.1f * static_cast<float>(k), z);
      }
    }
  }
  return pts;
}

}  // namespace scanplan::test

#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "scanplan/mapping/mls_map.hpp"

namespace scanplan::testing_support {

// Whether two MLS maps hold the same cells with the same surfaces: a map made anew in parts must
// be the map the same scans make from scratch. Heights agree to `tolerance_m` (0: bit for bit;
// a scan's points carried to the same place along another path differ in their last bits), the
// rest exactly.
inline ::testing::AssertionResult same_map(const MlsMap& a, const MlsMap& b,
                                           float tolerance_m = 0) {
  if (a.occupied_cells() != b.occupied_cells()) {
    return ::testing::AssertionFailure()
           << a.occupied_cells() << " occupied cells against " << b.occupied_cells();
  }
  if (a.extent() != b.extent()) return ::testing::AssertionFailure() << "the extents differ";
  std::string first_difference;
  a.for_each_cell([&](CellIndex c, const MlsCell& x) {
    if (!first_difference.empty()) return;
    const MlsCell* y = b.cell(c);
    const std::string at = "cell (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ")";
    if (!y) {
      first_difference = at + " is empty in the second map";
      return;
    }
    if (x.size != y->size || x.interpolated != y->interpolated) {
      first_difference = at + " holds other surfaces";
      return;
    }
    for (int k = 0; k < x.size; ++k) {
      const SurfacePatch& p = x.patches[k];
      const SurfacePatch& q = y->patches[k];
      const auto near = [&](float u, float v) { return std::abs(u - v) <= tolerance_m; };
      const float m2_tolerance = tolerance_m * static_cast<float>(p.count);
      if (!near(p.min_z, q.min_z) || !near(p.max_z, q.max_z) || !near(p.mean_z, q.mean_z) ||
          std::abs(p.m2 - q.m2) > m2_tolerance || p.count != q.count ||
          p.seen_from != q.seen_from) {
        first_difference = at + ", surface " + std::to_string(k) + " differs";
        return;
      }
    }
  });
  if (!first_difference.empty()) return ::testing::AssertionFailure() << first_difference;
  return ::testing::AssertionSuccess();
}

}  // namespace scanplan::testing_support

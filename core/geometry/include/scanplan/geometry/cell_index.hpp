#pragma once

#include <cstdint>

namespace scanplan {

// Integer cell coordinates of an x-y grid of side c: cell (i, j) covers [i·c, (i+1)·c) ×
// [j·c, (j+1)·c). The MLS map, the region rasters and the planner all index cells this way.
struct CellIndex {
  std::int32_t x = 0, y = 0;
  bool operator==(const CellIndex&) const = default;
};

}  // namespace scanplan

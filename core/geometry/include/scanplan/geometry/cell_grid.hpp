#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "scanplan/geometry/cell_index.hpp"

namespace scanplan {

// A dense raster of per-cell values over a rectangle of MLS cells: what the region
// computations produce and the top-view renderer draws. Row 0 is the lowest y.
template <typename T>
struct CellGrid {
  CellIndex origin;  // the cell at column 0, row 0
  int cols = 0, rows = 0;
  double cell_m = 1.0;
  std::vector<T> values;

  CellGrid() = default;
  CellGrid(CellIndex origin_, int cols_, int rows_, double cell, T fill)
      : origin(origin_),
        cols(cols_),
        rows(rows_),
        cell_m(cell),
        values(static_cast<std::size_t>(cols_) * rows_, fill) {}

  std::optional<std::size_t> offset(CellIndex c) const {
    const int i = c.x - origin.x, j = c.y - origin.y;
    if (i < 0 || j < 0 || i >= cols || j >= rows) return std::nullopt;
    return static_cast<std::size_t>(j) * cols + i;
  }
  CellIndex index_at(std::size_t offset) const {
    return {origin.x + static_cast<std::int32_t>(offset % cols),
            origin.y + static_cast<std::int32_t>(offset / cols)};
  }
};

}  // namespace scanplan

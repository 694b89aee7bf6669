#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace scanplan::cli {

// The regions of the paper's Fig. 4/5 as the server draws them in layers/regions.png.
enum class RegionClass : std::uint8_t {
  kUnknown,        // a pixel under a drawing (scan point, candidate ring, path, label)
  kOutside,        // outside the target region
  kUnscanned,      // U
  kCompleted,      // C: has data within the completed radius of a scan point
  kLowMovable,     // M, where the robot can drive
  kLowNotMovable,  // M, where it cannot
};

// A north-up raster of region classes georeferenced in the map frame: pixel (col, row) covers
// x in [x_min + col·m_per_px, +m_per_px) and y in (y_max - (row+1)·m_per_px, y_max - row·m_per_px].
struct RegionRaster {
  int width = 0, height = 0;
  double x_min = 0, y_max = 0, m_per_px = 0.25;
  std::vector<RegionClass> pixels;  // row-major, row 0 the northern edge

  RegionClass at(int col, int row) const {
    return pixels[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
                  static_cast<std::size_t>(col)];
  }
};

// Decodes GET /api/v1/layers/regions.png. The server draws it over the cells of the target
// region's bounding box (GET /api/v1/params "target"), `cell_m` metres a cell and `px_per_cell`
// pixels a cell (docs/api.md: 4 px a 1 m cell), cells indexed by floor(coordinate / cell_m).
// Each pixel is classified by its exact colour (core/mapping/src/top_view.cpp); drawings over the
// map are kUnknown. Throws std::runtime_error when the bytes are not a PNG or the image's size does
// not fit the target region (a plan made before the target changed).
RegionRaster decode_regions_png(const std::string& png, double target_min_x, double target_min_y,
                                double target_max_x, double target_max_y, double cell_m = 1.0,
                                int px_per_cell = 4);

}  // namespace scanplan::cli

#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "scanplan/mapping/height_range.hpp"
#include "scanplan/mapping/movable_region.hpp"
#include "scanplan/mapping/region_segmentation.hpp"

namespace scanplan {

// Top views of the map in the style of the paper's Fig. 4, 5 and 7, north (+y) up, one square
// of `px_per_cell` pixels per MLS cell, covering the target region's bounding box.
struct TopViewStyle {
  int px_per_cell = 4;
};

// Scan-completed cells flesh-coloured, low-resolution cells yellow where movable and blue where
// not, unscanned dark grey, outside the target region black; scan points as circles, the first
// blue and the latest red.
cv::Mat render_regions(const RegionMap& regions, const MovableRegion* movable,
                       const std::vector<Eigen::Vector2d>& scan_points,
                       const TopViewStyle& style = {});

// The lowest and highest top surface (the DEM height) of the target region's cells with data, in
// metres: the ends of the elevation view's colour scale. Nothing when no cell has data.
std::optional<HeightRange> elevation_range(const MlsMap& map, const RegionMap& regions);

// Height of the highest surface per cell (the DEM view), colour-mapped (turbo) over
// elevation_range; cells without data black.
cv::Mat render_elevation(const MlsMap& map, const RegionMap& regions,
                         const TopViewStyle& style = {});

// The movable region green over the cells that have data (grey).
cv::Mat render_movable(const MlsMap& map, const MovableRegion& movable, const RegionMap& regions,
                       const TopViewStyle& style = {});

std::vector<std::uint8_t> encode_png(const cv::Mat& bgr);

// A regions top view (render_regions, perhaps with a plan drawn over it) that explains itself
// outside the page (scanplan simulate's step images): `title` in a band above it and, below,
// the legend of its colours and marks and a scale bar.
cv::Mat captioned_regions(const cv::Mat& top_view, const RegionMap& regions,
                          const std::string& title, const TopViewStyle& style = {});

// The pixel of a map position in a top view of `regions`.
cv::Point top_view_pixel(const RegionMap& regions, const Eigen::Vector2d& p,
                         const TopViewStyle& style = {});

}  // namespace scanplan

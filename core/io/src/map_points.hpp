#pragma once

#include <bit>
#include <cstring>
#include <string>
#include <vector>

#include "scanplan/io/map_export.hpp"

namespace scanplan::detail {

// Appends `value`'s bytes, little-endian (both export formats are).
template <typename T>
void append_le(std::string& out, T value) {
  static_assert(std::endian::native == std::endian::little,
                "the map exports assume a little-endian host");
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

// Calls f(point, colour, scan id) for every point of `parts` in order; grey where a cloud has
// no colours.
template <typename F>
void for_each_map_point(const std::vector<MapPart>& parts, F&& f) {
  for (const MapPart& part : parts) {
    if (!part.points) continue;
    const PointCloud& cloud = *part.points;
    const bool colors = cloud.has_colors();
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      f(cloud.points[i], colors ? cloud.colors[i] : Rgb{128, 128, 128}, part.scan_id);
    }
  }
}

}  // namespace scanplan::detail

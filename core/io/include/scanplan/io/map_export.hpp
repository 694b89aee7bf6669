#pragma once

#include <cstdint>
#include <ctime>
#include <memory>
#include <string>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// One scan of the registered map, its points in the map frame (metres), for the exports other
// teams read (issue 18): every point carries the scan it came from.
struct MapPart {
  std::uint32_t scan_id = 0;
  std::shared_ptr<const PointCloud> points;  // grey where the cloud has no colours
};

// Binary little-endian PLY: x, y, z as float, red, green, blue as uchar and scan_id as uint per
// vertex, `comments` in the header (no line breaks: std::invalid_argument).
std::string map_ply_bytes(const std::vector<MapPart>& parts,
                          const std::vector<std::string>& comments = {});

// LAS 1.4 (ASPRS R15), point data record format 7: coordinates as int32 at millimetres from an
// offset at the map's minimum corner, RGB as 16 bits (the 8-bit colour × 257), point source id
// = the scan id (the ids must fit 16 bits: std::invalid_argument), one return per pulse. The map
// frame has no coordinate reference system: no WKT record is written. `created` dates the file
// (day of year and year in the header).
std::string map_las_bytes(const std::vector<MapPart>& parts, std::time_t created,
                          const std::string& software = "scanplan");

}  // namespace scanplan

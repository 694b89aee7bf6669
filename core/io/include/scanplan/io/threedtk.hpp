#pragma once

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <string>
#include <string_view>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan {

// Files of 3DTK ("The 3D Toolkit", slam6D): `.3d` scans, `.pose` odometry, `.reference`
// registered poses. 3DTK is left-handed with y up and works in centimetres; everything
// returned here is in our right-handed, z-up frame in metres.

// The change of basis C with p_ours = C * p_3dtk / 100, i.e. (x, y, z) -> (z, -x, y)/100.
// det(C) = -1: it flips handedness, so C·R·Cᵀ of a 3DTK rotation R is again a rotation.
Eigen::Matrix3d threedtk_to_ours_basis();

// Which returns a `.3d` reader keeps. 3DTK scanners report missed beams as points at or next
// to the origin; the default drops those and nothing else. (In the 3DTK sample scans the mount
// shows up at 9-20 cm and saturated beams at 32.76 m, which callers can cut with these.)
struct ThreedtkScanOptions {
  double min_range_m = 0.05;
  double max_range_m = std::numeric_limits<double>::infinity();
};

struct ThreedtkScanInfo {
  std::size_t lines = 0;               // non-blank lines, one point each
  std::size_t dropped_short = 0;       // nearer than min_range_m
  std::size_t dropped_far = 0;         // farther than max_range_m
  std::size_t dropped_non_finite = 0;  // NaN or infinite coordinate
};

// A `.3d` scan: one "x y z" (cm) per line. Points are converted to our frame; returns outside
// the options' range and non-finite points are dropped. Throws ScanFileError naming the file
// and line.
PointCloud read_threedtk_scan(const std::filesystem::path& file, ThreedtkScanInfo* info = nullptr,
                              const ThreedtkScanOptions& options = {});
PointCloud parse_threedtk_scan(std::string_view text, const std::string& source_name,
                               ThreedtkScanInfo* info = nullptr,
                               const ThreedtkScanOptions& options = {});

// A `.pose` file: line 1 "tx ty tz" (cm), line 2 "rx ry rz" (degrees, R = Rx·Ry·Rz), mapping
// scan points into 3DTK's world frame. Returned in our frame: (C·R·Cᵀ, C·t/100).
Eigen::Isometry3d read_threedtk_pose(const std::filesystem::path& file);
Eigen::Isometry3d parse_threedtk_pose(std::string_view text, const std::string& source_name);

// A `.reference` file: 16 numbers, a 4x4 column-major matrix with the translation in cm,
// optionally followed by a colour index. Returned in our frame like a pose.
Eigen::Isometry3d read_threedtk_reference(const std::filesystem::path& file);
Eigen::Isometry3d parse_threedtk_reference(std::string_view text, const std::string& source_name);

}  // namespace scanplan

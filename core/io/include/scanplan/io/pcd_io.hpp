#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan {

enum class PcdData { kAscii, kBinary, kBinaryCompressed };

// What a PCD header said beyond the points themselves.
struct PcdInfo {
  PcdData data = PcdData::kBinary;
  std::size_t width = 0, height = 0;
  std::size_t declared_points = 0;
  // tx ty tz qw qx qy qz, as in the file; the points are returned as stored, not moved by it
  // (PCL does the same).
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};
  std::size_t dropped_non_finite = 0;  // points left out for a NaN or infinite coordinate
};

// Reads a PCD file (v0.7, and older ones without VERSION/VIEWPOINT): DATA ascii, binary or
// binary_compressed (LZF); x y z as F4 or F8; colour from an `rgb` or `rgba` field of 4 bytes
// (any TYPE; the bits are 0x00RRGGBB, alpha ignored). Other fields are skipped. Points with a
// non-finite coordinate (organized clouds mark holes with NaN) are dropped.
// Throws ScanFileError naming the file and the header line or point that is wrong.
PointCloud read_pcd(const std::filesystem::path& file, PcdInfo* info = nullptr);
PointCloud read_pcd_bytes(std::string_view bytes, const std::string& source_name,
                          PcdInfo* info = nullptr);

// Writes FIELDS x y z (F4) and rgb (F4 holding 0x00RRGGBB, as PCL's PointXYZRGB) when the
// cloud has colours; DATA binary, or ascii when `binary` is false.
void write_pcd(const std::filesystem::path& file, const PointCloud& cloud, bool binary = true);
std::string write_pcd_bytes(const PointCloud& cloud, bool binary = true);

}  // namespace scanplan

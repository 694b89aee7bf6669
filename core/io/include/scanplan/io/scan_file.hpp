#pragma once

#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

#include "scanplan/geometry/point_cloud.hpp"

namespace scanplan {

// Thrown for a point-cloud file (PLY, PCD, 3DTK) that cannot be read or written. The message
// names the file, or the source name given for in-memory data, and says what is wrong, so it
// can be shown to an operator or returned in a 400 answer as it is.
class ScanFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Reads a scan of any supported kind, chosen by extension: .ply, .pcd or .3d (3DTK, converted
// to our frame and metres). The extension is matched without regard to case.
PointCloud read_point_cloud(const std::filesystem::path& file);

// Reads a PLY or PCD file held in memory (an HTTP body), telling them apart by their first
// bytes; `source_name` only labels error messages.
PointCloud read_point_cloud_bytes(std::string_view bytes, const std::string& source_name);

// The whole content of a file; the readers parse from memory so that files and HTTP bodies
// share one code path.
std::string read_scan_file_bytes(const std::filesystem::path& file);

// Writes `bytes` to `file` through a temporary file beside it and a rename, so that a process
// killed mid-write leaves either the old file or none, never a truncated scan under its name.
void write_scan_file_bytes(const std::filesystem::path& file, std::string_view bytes);

}  // namespace scanplan

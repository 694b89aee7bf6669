#pragma once

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan {

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

// What a PLY header said beyond the points themselves.
struct PlyInfo {
  PlyFormat format = PlyFormat::kBinaryLittleEndian;
  std::vector<std::string> comments;   // the text after "comment ", in file order
  std::vector<std::string> obj_info;   // the text after "obj_info ", in file order
  std::size_t vertex_count = 0;        // as declared by the header
  std::size_t dropped_non_finite = 0;  // vertices left out for a NaN or infinite coordinate
};

// Reads the vertex element of a PLY file (ascii, binary_little_endian, binary_big_endian):
// x, y, z as float or double; colour from uchar red/green/blue (or r/g/b, diffuse_red/...)
// when all three are present. Other vertex properties and other elements are skipped.
// Vertices with a non-finite coordinate are dropped and counted in `info`.
// Throws ScanFileError naming the file and the header line or vertex that is wrong.
PointCloud read_ply(const std::filesystem::path& file, PlyInfo* info = nullptr);
PointCloud read_ply_bytes(std::string_view bytes, const std::string& source_name,
                          PlyInfo* info = nullptr);

// Writes x y z as float, and red green blue as uchar when the cloud has colours. A comment
// may not contain a line break (std::invalid_argument).
void write_ply(const std::filesystem::path& file, const PointCloud& cloud,
               const std::vector<std::string>& comments = {},
               PlyFormat format = PlyFormat::kBinaryLittleEndian);
std::string write_ply_bytes(const PointCloud& cloud, const std::vector<std::string>& comments = {},
                            PlyFormat format = PlyFormat::kBinaryLittleEndian);

}  // namespace scanplan

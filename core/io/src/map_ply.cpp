#include <stdexcept>

#include "map_points.hpp"
#include "scanplan/io/map_export.hpp"

namespace scanplan {
using detail::append_le;

std::string map_ply_bytes(const std::vector<MapPart>& parts,
                          const std::vector<std::string>& comments) {
  std::size_t count = 0;
  for (const MapPart& part : parts) count += part.points ? part.points->size() : 0;
  std::string out = "ply\nformat binary_little_endian 1.0\n";
  for (const std::string& c : comments) {
    if (c.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument("a PLY comment may not contain a line break: '" + c + "'");
    }
    out += "comment " + c + "\n";
  }
  out += "element vertex " + std::to_string(count) + "\n";
  out +=
      "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
      "property uchar green\nproperty uchar blue\nproperty uint scan_id\nend_header\n";
  out.reserve(out.size() + count * 19);
  detail::for_each_map_point(parts, [&](const Eigen::Vector3f& p, const Rgb& c, std::uint32_t id) {
    append_le(out, p.x());
    append_le(out, p.y());
    append_le(out, p.z());
    out.append(reinterpret_cast<const char*>(c.data()), 3);
    append_le(out, id);
  });
  return out;
}

}  // namespace scanplan

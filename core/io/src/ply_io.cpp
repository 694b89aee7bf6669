#include "scanplan/io/ply_io.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <utility>

#include "text_scan.hpp"

namespace scanplan {
namespace {

enum class ScalarType { kInt8, kUint8, kInt16, kUint16, kInt32, kUint32, kFloat32, kFloat64 };

std::size_t size_of(ScalarType t) {
  switch (t) {
    case ScalarType::kInt8:
    case ScalarType::kUint8:
      return 1;
    case ScalarType::kInt16:
    case ScalarType::kUint16:
      return 2;
    case ScalarType::kInt32:
    case ScalarType::kUint32:
    case ScalarType::kFloat32:
      return 4;
    case ScalarType::kFloat64:
      return 8;
  }
  return 1;
}

bool is_integer(ScalarType t) {
  return t != ScalarType::kFloat32 && t != ScalarType::kFloat64;
}

std::optional<ScalarType> parse_type(std::string_view name) {
  // Both the original PLY names and the sized aliases that newer writers (e.g. Open3D) use.
  static constexpr std::array<std::pair<std::string_view, ScalarType>, 16> kNames{{
      {"char", ScalarType::kInt8},
      {"int8", ScalarType::kInt8},
      {"uchar", ScalarType::kUint8},
      {"uint8", ScalarType::kUint8},
      {"short", ScalarType::kInt16},
      {"int16", ScalarType::kInt16},
      {"ushort", ScalarType::kUint16},
      {"uint16", ScalarType::kUint16},
      {"int", ScalarType::kInt32},
      {"int32", ScalarType::kInt32},
      {"uint", ScalarType::kUint32},
      {"uint32", ScalarType::kUint32},
      {"float", ScalarType::kFloat32},
      {"float32", ScalarType::kFloat32},
      {"double", ScalarType::kFloat64},
      {"float64", ScalarType::kFloat64},
  }};
  for (const auto& [n, t] : kNames) {
    if (n == name) return t;
  }
  return std::nullopt;
}

struct Property {
  std::string name;
  ScalarType type = ScalarType::kFloat32;  // the item type for a list
  bool is_list = false;
  ScalarType count_type = ScalarType::kUint8;
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

struct Header {
  std::optional<PlyFormat> format;
  std::vector<std::string> comments;
  std::vector<std::string> obj_info;
  std::vector<Element> elements;
  std::size_t data_offset = 0;  // first byte after the end_header line
  std::size_t line_count = 0;   // so that ascii body line numbers match a text editor's
};

// Which output a vertex property feeds: coordinate `index` (x, y, z), colour channel `index`
// (red, green, blue), or neither.
struct Role {
  enum Output { kSkip, kXyz, kRgb } output = kSkip;
  std::size_t index = 0;
};

class Parser : private text_scan::LineReader {
 public:
  using LineReader::LineReader;

  PointCloud parse(PlyInfo* info);

 private:
  Header parse_header();
  void format_line(const std::vector<std::string_view>& tok, Header& h);
  void element_line(const std::vector<std::string_view>& tok, Header& h);
  void property_line(const std::vector<std::string_view>& tok, Header& h);
  std::vector<Role> vertex_roles(const Element& vertex, bool& has_color) const;
  void skip_binary(const Element& e, bool swap);
  void skip_ascii(const Element& e);
  void read_binary_vertices(const Element& e, const std::vector<Role>& roles, bool swap,
                            bool has_color, PointCloud& cloud, std::size_t& dropped);
  void read_ascii_vertices(const Element& e, const std::vector<Role>& roles, bool has_color,
                           PointCloud& cloud, std::size_t& dropped);
};

// The text after a keyword and its one separating blank, kept verbatim so comments round-trip.
std::string rest_after(std::string_view line, std::string_view keyword) {
  if (line.size() <= keyword.size() + 1) return {};
  return std::string(line.substr(keyword.size() + 1));
}

template <typename T>
T load(const char* p, bool swap) {
  std::array<char, sizeof(T)> buf;
  std::memcpy(buf.data(), p, sizeof(T));
  if (swap) std::reverse(buf.begin(), buf.end());
  T v;
  std::memcpy(&v, buf.data(), sizeof(T));
  return v;
}

double load_scalar(const char* p, ScalarType t, bool swap) {
  switch (t) {
    case ScalarType::kInt8:
      return load<std::int8_t>(p, swap);
    case ScalarType::kUint8:
      return load<std::uint8_t>(p, swap);
    case ScalarType::kInt16:
      return load<std::int16_t>(p, swap);
    case ScalarType::kUint16:
      return load<std::uint16_t>(p, swap);
    case ScalarType::kInt32:
      return load<std::int32_t>(p, swap);
    case ScalarType::kUint32:
      return load<std::uint32_t>(p, swap);
    case ScalarType::kFloat32:
      return load<float>(p, swap);
    case ScalarType::kFloat64:
      return load<double>(p, swap);
  }
  return 0;
}

const char* format_name(PlyFormat f) {
  switch (f) {
    case PlyFormat::kAscii:
      return "ascii";
    case PlyFormat::kBinaryLittleEndian:
      return "binary_little_endian";
    case PlyFormat::kBinaryBigEndian:
      return "binary_big_endian";
  }
  return "?";
}

Header Parser::parse_header() {
  Header h;
  std::string_view line;
  if (!next_line(line) || line != "ply") {
    fail("not a PLY file: the first line must be 'ply'");
  }
  while (true) {
    if (!next_line(line)) {
      fail("the header has no 'end_header' line (the file is truncated or not a PLY file)");
    }
    const auto tok = text_scan::split_ws(line);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];
    if (key == "end_header") {
      break;
    } else if (key == "comment") {
      h.comments.push_back(rest_after(line, key));
    } else if (key == "obj_info") {
      h.obj_info.push_back(rest_after(line, key));
    } else if (key == "format") {
      format_line(tok, h);
    } else if (key == "element") {
      element_line(tok, h);
    } else if (key == "property") {
      property_line(tok, h);
    } else {
      fail_line(line_, "unexpected header line '" + std::string(line.substr(0, 60)) + "'");
    }
  }
  if (!h.format) fail("the header has no 'format' line");
  h.data_offset = pos_;
  h.line_count = line_;
  return h;
}

void Parser::format_line(const std::vector<std::string_view>& tok, Header& h) {
  if (tok.size() != 3) fail_line(line_, "expected 'format <type> 1.0'");
  if (h.format) fail_line(line_, "a second 'format' line");
  if (tok[1] == "ascii") {
    h.format = PlyFormat::kAscii;
  } else if (tok[1] == "binary_little_endian") {
    h.format = PlyFormat::kBinaryLittleEndian;
  } else if (tok[1] == "binary_big_endian") {
    h.format = PlyFormat::kBinaryBigEndian;
  } else {
    fail_line(line_, "unknown format '" + std::string(tok[1]) +
                         "' (expected ascii, binary_little_endian or binary_big_endian)");
  }
  if (tok[2] != "1.0" && tok[2] != "1") {
    fail_line(line_, "unsupported PLY version '" + std::string(tok[2]) + "' (expected 1.0)");
  }
}

void Parser::element_line(const std::vector<std::string_view>& tok, Header& h) {
  if (tok.size() != 3) fail_line(line_, "expected 'element <name> <count>'");
  Element e;
  e.name = tok[1];
  // Unlike the values in an ascii body, a count may not carry a '+'.
  if (tok[2].starts_with('+') || !text_scan::parse_int(tok[2], e.count)) {
    fail_line(line_, "element '" + e.name + "' count '" + std::string(tok[2]) +
                         "' is not a non-negative integer");
  }
  for (const auto& other : h.elements) {
    if (other.name == e.name) fail_line(line_, "a second element named '" + e.name + "'");
  }
  h.elements.push_back(std::move(e));
}

void Parser::property_line(const std::vector<std::string_view>& tok, Header& h) {
  if (h.elements.empty()) fail_line(line_, "'property' before any 'element'");
  Property p;
  if (tok.size() >= 2 && tok[1] == "list") {
    if (tok.size() != 5) {
      fail_line(line_, "expected 'property list <count type> <item type> <name>'");
    }
    const auto ct = parse_type(tok[2]);
    const auto it = parse_type(tok[3]);
    if (!ct || !is_integer(*ct)) {
      fail_line(line_, "list count type '" + std::string(tok[2]) + "' is not an integer type");
    }
    if (!it) fail_line(line_, "unknown property type '" + std::string(tok[3]) + "'");
    p.is_list = true;
    p.count_type = *ct;
    p.type = *it;
    p.name = tok[4];
  } else {
    if (tok.size() != 3) fail_line(line_, "expected 'property <type> <name>'");
    const auto t = parse_type(tok[1]);
    if (!t) fail_line(line_, "unknown property type '" + std::string(tok[1]) + "'");
    p.type = *t;
    p.name = tok[2];
  }
  auto& props = h.elements.back().properties;
  for (const auto& other : props) {
    if (other.name == p.name) {
      fail_line(line_, "property '" + p.name + "' appears twice in element '" +
                           h.elements.back().name + "'");
    }
  }
  props.push_back(std::move(p));
}

std::vector<Role> Parser::vertex_roles(const Element& vertex, bool& has_color) const {
  std::vector<Role> roles(vertex.properties.size());
  auto find = [&](std::string_view name) -> std::optional<std::size_t> {
    for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
      if (vertex.properties[i].name == name) return i;
    }
    return std::nullopt;
  };
  auto property_list = [&] {
    std::string names;
    for (const auto& p : vertex.properties) names += (names.empty() ? "" : " ") + p.name;
    return names.empty() ? std::string("none") : names;
  };

  static constexpr std::array<const char*, 3> kAxisNames{"x", "y", "z"};
  for (std::size_t a = 0; a < 3; ++a) {
    const char* name = kAxisNames[a];
    const auto i = find(name);
    if (!i) {
      fail("the vertex element has no '" + std::string(name) +
           "' property (it has: " + property_list() + ")");
    }
    const Property& p = vertex.properties[*i];
    if (p.is_list || is_integer(p.type)) {
      fail("vertex property '" + p.name + "' must be a float or double scalar");
    }
    roles[*i] = {Role::kXyz, a};
  }

  // Writers disagree on colour names; take the first naming of which any part is present.
  static constexpr std::array<std::array<const char*, 3>, 3> kColorNames{{
      {"red", "green", "blue"},
      {"r", "g", "b"},
      {"diffuse_red", "diffuse_green", "diffuse_blue"},
  }};
  has_color = false;
  for (const auto& names : kColorNames) {
    std::array<std::optional<std::size_t>, 3> idx{find(names[0]), find(names[1]), find(names[2])};
    const bool any = idx[0] || idx[1] || idx[2];
    if (!any) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      if (!idx[c]) {
        fail("the vertex element has colour properties " + std::string(names[0]) + "/" + names[1] +
             "/" + names[2] + " but '" + names[c] + "' is missing");
      }
      const Property& p = vertex.properties[*idx[c]];
      if (p.is_list || p.type != ScalarType::kUint8) {
        fail("vertex property '" + p.name + "' must be uchar (0-255) to be read as a colour");
      }
      roles[*idx[c]] = {Role::kRgb, c};
    }
    has_color = true;
    break;
  }
  return roles;
}

void Parser::skip_binary(const Element& e, bool swap) {
  const std::size_t remaining = bytes_.size() - pos_;
  const bool has_list = std::any_of(e.properties.begin(), e.properties.end(),
                                    [](const Property& p) { return p.is_list; });
  if (!has_list) {
    std::size_t item = 0;
    for (const auto& p : e.properties) item += size_of(p.type);
    if (item == 0) return;
    if (e.count > remaining / item) {
      fail("element '" + e.name + "' declares " + std::to_string(e.count) + " items of " +
           std::to_string(item) + " bytes but only " + std::to_string(remaining) +
           " bytes remain (the file is truncated or the count is wrong)");
    }
    pos_ += static_cast<std::size_t>(e.count) * item;
    return;
  }
  // Each item takes at least one byte, so a lying count ends at the end of the data.
  for (std::uint64_t i = 0; i < e.count; ++i) {
    for (const auto& p : e.properties) {
      const std::size_t left = bytes_.size() - pos_;
      if (!p.is_list) {
        if (size_of(p.type) > left) {
          fail("the data ends inside element '" + e.name + "' item " + std::to_string(i));
        }
        pos_ += size_of(p.type);
        continue;
      }
      if (size_of(p.count_type) > left) {
        fail("the data ends inside element '" + e.name + "' item " + std::to_string(i));
      }
      const double n = load_scalar(bytes_.data() + pos_, p.count_type, swap);
      pos_ += size_of(p.count_type);
      if (n < 0 || n > static_cast<double>((bytes_.size() - pos_) / size_of(p.type))) {
        fail("element '" + e.name + "' item " + std::to_string(i) + " has a list of " +
             std::to_string(static_cast<long long>(n)) + " items, more than the data holds");
      }
      pos_ += static_cast<std::size_t>(n) * size_of(p.type);
    }
  }
}

void Parser::skip_ascii(const Element& e) {
  std::string_view line;
  for (std::uint64_t i = 0; i < e.count;) {
    if (!next_line(line)) {
      fail("the data ends after " + std::to_string(i) + " of " + std::to_string(e.count) + " '" +
           e.name + "' items");
    }
    if (!text_scan::split_ws(line).empty()) ++i;
  }
}

// Adds a vertex read as doubles to `cloud`, or counts it in `dropped` if it is not finite as
// floats.
void add_vertex(const std::array<double, 3>& xyz, const Rgb& rgb, bool has_color, PointCloud& cloud,
                std::size_t& dropped) {
  const Eigen::Vector3f pt(static_cast<float>(xyz[0]), static_cast<float>(xyz[1]),
                           static_cast<float>(xyz[2]));
  if (!pt.allFinite()) {
    ++dropped;
    return;
  }
  cloud.points.push_back(pt);
  if (has_color) cloud.colors.push_back(rgb);
}

void Parser::read_binary_vertices(const Element& e, const std::vector<Role>& roles, bool swap,
                                  bool has_color, PointCloud& cloud, std::size_t& dropped) {
  std::size_t min_item = 0;
  bool has_list = false;
  for (const auto& p : e.properties) {
    min_item += p.is_list ? size_of(p.count_type) : size_of(p.type);
    has_list = has_list || p.is_list;
  }
  const std::size_t remaining = bytes_.size() - pos_;
  // Checked before reserving, so a header that lies about the count cannot make us allocate.
  if (e.count > remaining / min_item) {
    fail("the header declares " + std::to_string(e.count) + " vertices of " +
         (has_list ? "at least " : "") + std::to_string(min_item) + " bytes but only " +
         std::to_string(remaining) +
         " bytes of data follow (the file is truncated or the count is wrong)");
  }
  const auto n = static_cast<std::size_t>(e.count);
  cloud.points.reserve(n);
  if (has_color) cloud.colors.reserve(n);

  std::array<double, 3> xyz{};
  Rgb rgb{};
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      const std::size_t left = bytes_.size() - pos_;
      if (p.is_list) {
        if (size_of(p.count_type) > left) {
          fail("the data ends inside vertex " + std::to_string(i));
        }
        const double count = load_scalar(bytes_.data() + pos_, p.count_type, swap);
        pos_ += size_of(p.count_type);
        if (count < 0 || count > static_cast<double>((bytes_.size() - pos_) / size_of(p.type))) {
          fail("vertex " + std::to_string(i) + " property '" + p.name + "' has a list of " +
               std::to_string(static_cast<long long>(count)) + " items, more than the data holds");
        }
        pos_ += static_cast<std::size_t>(count) * size_of(p.type);
        continue;
      }
      if (size_of(p.type) > left) fail("the data ends inside vertex " + std::to_string(i));
      const char* at = bytes_.data() + pos_;
      const Role role = roles[k];
      if (role.output == Role::kXyz) {
        xyz[role.index] = load_scalar(at, p.type, swap);
      } else if (role.output == Role::kRgb) {
        rgb[role.index] = static_cast<std::uint8_t>(*at);
      }
      pos_ += size_of(p.type);
    }
    add_vertex(xyz, rgb, has_color, cloud, dropped);
  }
}

void Parser::read_ascii_vertices(const Element& e, const std::vector<Role>& roles, bool has_color,
                                 PointCloud& cloud, std::size_t& dropped) {
  // Every property takes at least one character and one separator.
  const std::size_t remaining = bytes_.size() - pos_;
  const std::size_t min_item = 2 * e.properties.size();
  if (e.count > (remaining + 1) / min_item) {
    fail("the header declares " + std::to_string(e.count) + " vertices but only " +
         std::to_string(remaining) +
         " bytes of data follow (the file is truncated or the count is wrong)");
  }
  const auto n = static_cast<std::size_t>(e.count);
  cloud.points.reserve(n);
  if (has_color) cloud.colors.reserve(n);

  std::string_view line;
  std::array<double, 3> xyz{};
  Rgb rgb{};
  for (std::size_t i = 0; i < n;) {
    if (!next_line(line)) {
      fail("the data ends after " + std::to_string(i) + " of " + std::to_string(n) +
           " vertices (the file is truncated or the count is wrong)");
    }
    const auto tok = text_scan::split_ws(line);
    if (tok.empty()) continue;
    std::size_t t = 0;
    auto value_count_error = [&] {
      fail_line(line_, "vertex " + std::to_string(i) + " has " + std::to_string(tok.size()) +
                           " values, which does not match the header's properties");
    };
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const Property& p = e.properties[k];
      if (t >= tok.size()) value_count_error();
      if (p.is_list) {
        std::int64_t count = 0;
        if (!text_scan::parse_int(tok[t], count) || count < 0) {
          fail_line(line_, "list length '" + std::string(tok[t]) + "' of property '" + p.name +
                               "' is not a non-negative integer");
        }
        ++t;
        if (static_cast<std::uint64_t>(count) > tok.size() - t) value_count_error();
        t += static_cast<std::size_t>(count);
        continue;
      }
      const std::string_view v = tok[t++];
      const Role role = roles[k];
      if (role.output == Role::kXyz) {
        if (!text_scan::parse_double(v, xyz[role.index])) {
          fail_line(line_, "vertex " + std::to_string(i) + " property '" + p.name + "': '" +
                               std::string(v.substr(0, 40)) + "' is not a number");
        }
      } else if (role.output == Role::kRgb) {
        std::int64_t c = 0;
        if (!text_scan::parse_int(v, c) || c < 0 || c > 255) {
          fail_line(line_, "vertex " + std::to_string(i) + " colour '" + p.name + "': '" +
                               std::string(v.substr(0, 40)) + "' is not an integer 0-255");
        }
        rgb[role.index] = static_cast<std::uint8_t>(c);
      }
    }
    if (t != tok.size()) value_count_error();
    ++i;
    add_vertex(xyz, rgb, has_color, cloud, dropped);
  }
}

PointCloud Parser::parse(PlyInfo* info) {
  const Header h = parse_header();
  const Element* vertex = nullptr;
  std::size_t vertex_index = 0;
  for (std::size_t i = 0; i < h.elements.size(); ++i) {
    if (h.elements[i].name == "vertex") {
      vertex = &h.elements[i];
      vertex_index = i;
    }
  }
  if (!vertex) fail("the header declares no 'vertex' element");
  bool has_color = false;
  const std::vector<Role> roles = vertex_roles(*vertex, has_color);

  const PlyFormat format = *h.format;
  const bool file_big = format == PlyFormat::kBinaryBigEndian;
  const bool swap = file_big != (std::endian::native == std::endian::big);

  PointCloud cloud;
  std::size_t dropped = 0;
  // Elements after the vertices are not needed, so they are neither read nor checked.
  for (std::size_t i = 0; i < vertex_index; ++i) {
    if (format == PlyFormat::kAscii) {
      skip_ascii(h.elements[i]);
    } else {
      skip_binary(h.elements[i], swap);
    }
  }
  if (format == PlyFormat::kAscii) {
    read_ascii_vertices(*vertex, roles, has_color, cloud, dropped);
  } else {
    read_binary_vertices(*vertex, roles, swap, has_color, cloud, dropped);
  }

  if (info) {
    info->format = format;
    info->comments = h.comments;
    info->obj_info = h.obj_info;
    info->vertex_count = static_cast<std::size_t>(vertex->count);
    info->dropped_non_finite = dropped;
  }
  return cloud;
}

template <typename T>
void append_binary(std::string& out, T v, bool swap) {
  std::array<char, sizeof(T)> buf;
  std::memcpy(buf.data(), &v, sizeof(T));
  if (swap) std::reverse(buf.begin(), buf.end());
  out.append(buf.data(), buf.size());
}

}  // namespace

PointCloud read_ply_bytes(std::string_view bytes, const std::string& source_name, PlyInfo* info) {
  return Parser(bytes, source_name).parse(info);
}

PointCloud read_ply(const std::filesystem::path& file, PlyInfo* info) {
  const std::string bytes = read_scan_file_bytes(file);
  return read_ply_bytes(bytes, file.string(), info);
}

std::string write_ply_bytes(const PointCloud& cloud, const std::vector<std::string>& comments,
                            PlyFormat format) {
  for (const auto& c : comments) {
    if (c.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument("a PLY comment may not contain a line break: '" + c + "'");
    }
  }
  const bool colors = cloud.has_colors();
  std::string out = "ply\nformat ";
  out += format_name(format);
  out += " 1.0\n";
  for (const auto& c : comments) out += "comment " + c + "\n";
  out += "element vertex " + std::to_string(cloud.size()) + "\n";
  out += "property float x\nproperty float y\nproperty float z\n";
  if (colors) out += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  out += "end_header\n";

  if (format == PlyFormat::kAscii) {
    out.reserve(out.size() + cloud.size() * (colors ? 48 : 36));
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const auto& p = cloud.points[i];
      text_scan::append_text(out, p.x());
      out += ' ';
      text_scan::append_text(out, p.y());
      out += ' ';
      text_scan::append_text(out, p.z());
      if (colors) {
        for (const std::uint8_t c : cloud.colors[i]) {
          out += ' ';
          out += std::to_string(c);
        }
      }
      out += '\n';
    }
    return out;
  }

  const bool swap =
      (format == PlyFormat::kBinaryBigEndian) != (std::endian::native == std::endian::big);
  out.reserve(out.size() + cloud.size() * (colors ? 15 : 12));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    append_binary(out, p.x(), swap);
    append_binary(out, p.y(), swap);
    append_binary(out, p.z(), swap);
    if (colors) out.append(reinterpret_cast<const char*>(cloud.colors[i].data()), 3);
  }
  return out;
}

void write_ply(const std::filesystem::path& file, const PointCloud& cloud,
               const std::vector<std::string>& comments, PlyFormat format) {
  write_scan_file_bytes(file, write_ply_bytes(cloud, comments, format));
}

}  // namespace scanplan

#include "scanplan/io/pcd_io.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "text_scan.hpp"

namespace scanplan {
namespace {

struct Field {
  std::string name;
  std::size_t size = 0;
  char type = 'F';
  std::size_t count = 1;
};

struct Header {
  std::vector<Field> fields;
  std::uint64_t width = 0, height = 1, points = 0;
  std::array<double, 7> viewpoint{0, 0, 0, 1, 0, 0, 0};
  PcdData data = PcdData::kBinary;
};

// Where the fields we use sit: in a point's bytes (binary), or among its values (ascii).
struct Layout {
  std::size_t point_size = 0;             // bytes per point
  std::size_t values_per_point = 0;       // ascii tokens per point
  std::array<std::size_t, 3> xyz{};       // field indices
  std::optional<std::size_t> rgb;         // field index
  std::vector<std::size_t> byte_offset;   // per field, within a point
  std::vector<std::size_t> value_offset;  // per field, within an ascii line
};

// Compressed PCD bodies are larger than this many times their LZF input only if they lie:
// LZF's longest back reference writes 264 bytes from a 3-byte instruction.
constexpr std::uint64_t kMaxLzfRatio = 88;

// LZF (liblzf, as PCL writes it). Returns false on a malformed stream or one that does not
// fill `out` exactly.
bool lzf_decompress(std::string_view in, std::vector<char>& out) {
  std::size_t ip = 0, op = 0;
  while (ip < in.size()) {
    const auto ctrl = static_cast<unsigned char>(in[ip++]);
    if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
      const std::size_t len = ctrl + 1u;
      if (len > in.size() - ip || len > out.size() - op) return false;
      std::memcpy(out.data() + op, in.data() + ip, len);
      ip += len;
      op += len;
      continue;
    }
    std::size_t len = ctrl >> 5;  // a back reference
    if (ip >= in.size()) return false;
    if (len == 7) {
      len += static_cast<unsigned char>(in[ip++]);
      if (ip >= in.size()) return false;
    }
    const std::size_t back = ((ctrl & 0x1fu) << 8) + static_cast<unsigned char>(in[ip++]) + 1;
    len += 2;
    if (back > op || len > out.size() - op) return false;
    // Byte by byte: the source may overlap what is being written (run-length encoding).
    for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - back];
  }
  return op == out.size();
}

class Parser : private text_scan::LineReader {
 public:
  using LineReader::LineReader;

  PointCloud parse(PcdInfo* info);

 private:
  // What the header's lines said, before they are checked against each other.
  struct HeaderLines {
    bool fields = false, size = false, type = false, count = false;
    bool width = false, height = false, points = false, viewpoint = false;
    std::vector<std::size_t> sizes, counts;
    std::vector<char> types;
  };
  Header parse_header();
  // One header line; true once it is the DATA line, which ends the header.
  bool header_line(std::string_view line, Header& h, HeaderLines& seen);
  void per_field_line(std::string_view key, const std::vector<std::string_view>& args,
                      HeaderLines& seen);
  void data_line(const std::vector<std::string_view>& args, Header& h);
  // The lines checked against each other: one SIZE, TYPE and COUNT per field, WIDTH × HEIGHT
  // = POINTS.
  void complete(Header& h, const HeaderLines& seen);
  Layout layout_of(const Header& h) const;
  void read_ascii(const Header& h, const Layout& l, PointCloud& cloud, std::size_t& dropped);
  void read_binary(const Header& h, const Layout& l, PointCloud& cloud, std::size_t& dropped);
  void read_compressed(const Header& h, const Layout& l, PointCloud& cloud, std::size_t& dropped);
};

// PCL has written ascii rgb both as the float whose bits are the colour (old) and as the
// integer itself (since 1.8, because some colours are NaN as floats); accept either.
bool parse_rgb_token(std::string_view s, char type, std::uint32_t& bits) {
  std::uint32_t u = 0;
  if (text_scan::parse_int(s, u)) {
    bits = u;
    return true;
  }
  if (type == 'I') {
    std::int32_t i = 0;
    if (!text_scan::parse_int(s, i)) return false;
    bits = static_cast<std::uint32_t>(i);
    return true;
  }
  if (type != 'F') return false;
  double d = 0;
  if (!text_scan::parse_double(s, d)) return false;
  const auto f = static_cast<float>(d);
  std::memcpy(&bits, &f, sizeof bits);
  return true;
}

template <typename T>
T load_le(const char* p) {
  std::array<char, sizeof(T)> buf;
  std::memcpy(buf.data(), p, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(buf.begin(), buf.end());
  T v;
  std::memcpy(&v, buf.data(), sizeof(T));
  return v;
}

template <typename T>
void append_le(std::string& out, T v) {
  std::array<char, sizeof(T)> buf;
  std::memcpy(buf.data(), &v, sizeof(T));
  if constexpr (std::endian::native == std::endian::big) std::reverse(buf.begin(), buf.end());
  out.append(buf.data(), buf.size());
}

Rgb unpack_rgb(std::uint32_t bits) {
  return {static_cast<std::uint8_t>(bits >> 16), static_cast<std::uint8_t>(bits >> 8),
          static_cast<std::uint8_t>(bits)};
}

Header Parser::parse_header() {
  Header h;
  HeaderLines seen;
  std::string_view line;
  do {
    if (!next_line(line)) {
      fail("the header has no 'DATA' line (the file is truncated or not a PCD file)");
    }
  } while (!header_line(line, h, seen));
  complete(h, seen);
  return h;
}

bool Parser::header_line(std::string_view line, Header& h, HeaderLines& seen) {
  const auto tok = text_scan::split_ws(line);
  if (tok.empty() || tok[0].front() == '#') return false;
  const std::string_view key = tok[0];
  const auto args = std::vector<std::string_view>(tok.begin() + 1, tok.end());
  auto once = [&](bool& flag, std::string_view name) {
    if (flag) fail_line(line_, "a second '" + std::string(name) + "' line");
    flag = true;
  };
  auto count_line = [&](bool& flag, std::uint64_t& out) {
    once(flag, key);
    if (args.size() != 1 || !text_scan::parse_int(args[0], out)) {
      fail_line(line_, "'" + std::string(key) + "' needs one non-negative integer");
    }
  };
  if (key == "VERSION") {
    // 0.5 to 0.7 differ only in optional lines, which are handled below.
  } else if (key == "FIELDS" || key == "COLUMNS") {
    once(seen.fields, "FIELDS");
    if (args.empty()) fail_line(line_, "FIELDS names no fields");
    for (const auto a : args) h.fields.push_back(Field{std::string(a), 0, 'F', 1});
  } else if (key == "SIZE" || key == "TYPE" || key == "COUNT") {
    per_field_line(key, args, seen);
  } else if (key == "WIDTH") {
    count_line(seen.width, h.width);
  } else if (key == "HEIGHT") {
    count_line(seen.height, h.height);
  } else if (key == "POINTS") {
    count_line(seen.points, h.points);
  } else if (key == "VIEWPOINT") {
    once(seen.viewpoint, key);
    if (args.size() != 7) fail_line(line_, "VIEWPOINT needs 7 numbers: tx ty tz qw qx qy qz");
    for (std::size_t i = 0; i < 7; ++i) {
      if (!text_scan::parse_double(args[i], h.viewpoint[i])) {
        fail_line(line_, "VIEWPOINT value '" + std::string(args[i]) + "' is not a number");
      }
    }
  } else if (key == "DATA") {
    data_line(args, h);
    return true;
  } else {
    fail_line(line_, "unexpected header line '" + std::string(line.substr(0, 60)) + "'");
  }
  return false;
}

void Parser::per_field_line(std::string_view key, const std::vector<std::string_view>& args,
                            HeaderLines& seen) {
  bool& flag = key == "SIZE" ? seen.size : key == "TYPE" ? seen.type : seen.count;
  if (flag) fail_line(line_, "a second '" + std::string(key) + "' line");
  flag = true;
  for (const auto a : args) {
    if (key == "SIZE") {
      std::size_t v = 0;
      if (!text_scan::parse_int(a, v) || (v != 1 && v != 2 && v != 4 && v != 8)) {
        fail_line(line_, "SIZE '" + std::string(a) + "' is not 1, 2, 4 or 8");
      }
      seen.sizes.push_back(v);
    } else if (key == "TYPE") {
      if (a.size() != 1 || (a[0] != 'F' && a[0] != 'I' && a[0] != 'U')) {
        fail_line(line_, "TYPE '" + std::string(a) + "' is not F, I or U");
      }
      seen.types.push_back(a[0]);
    } else {
      std::size_t c = 0;
      // The longest descriptors PCL knows have a few hundred values; a million is a lie.
      if (!text_scan::parse_int(a, c) || c == 0 || c > (1u << 20)) {
        fail_line(line_, "COUNT '" + std::string(a) + "' is not an integer from 1 to 1048576");
      }
      seen.counts.push_back(c);
    }
  }
}

void Parser::data_line(const std::vector<std::string_view>& args, Header& h) {
  if (args.size() != 1) fail_line(line_, "expected 'DATA ascii|binary|binary_compressed'");
  if (args[0] == "ascii") {
    h.data = PcdData::kAscii;
  } else if (args[0] == "binary") {
    h.data = PcdData::kBinary;
  } else if (args[0] == "binary_compressed") {
    h.data = PcdData::kBinaryCompressed;
  } else {
    fail_line(line_, "unknown DATA '" + std::string(args[0]) +
                         "' (expected ascii, binary or binary_compressed)");
  }
}

void Parser::complete(Header& h, const HeaderLines& seen) {
  if (!seen.fields) fail("the header has no FIELDS line");
  if (!seen.size) fail("the header has no SIZE line");
  if (!seen.type) fail("the header has no TYPE line");
  const std::size_t n = h.fields.size();
  auto check_len = [&](std::size_t got, const char* what) {
    if (got != n) {
      fail(std::string(what) + " has " + std::to_string(got) + " entries but FIELDS has " +
           std::to_string(n));
    }
  };
  check_len(seen.sizes.size(), "SIZE");
  check_len(seen.types.size(), "TYPE");
  if (seen.count) check_len(seen.counts.size(), "COUNT");
  for (std::size_t i = 0; i < n; ++i) {
    h.fields[i].size = seen.sizes[i];
    h.fields[i].type = seen.types[i];
    h.fields[i].count = seen.count ? seen.counts[i] : 1;
    if (seen.types[i] == 'F' && seen.sizes[i] != 4 && seen.sizes[i] != 8) {
      fail("field '" + h.fields[i].name + "' has TYPE F with SIZE " +
           std::to_string(seen.sizes[i]) + " (floats are 4 or 8 bytes)");
    }
  }
  if (!seen.width && !seen.points) fail("the header has neither WIDTH nor POINTS");
  if (!seen.width) {
    h.width = h.points;
    h.height = 1;
  }
  std::uint64_t wh = 0;
  if (__builtin_mul_overflow(h.width, h.height, &wh)) {
    fail("WIDTH " + std::to_string(h.width) + " times HEIGHT " + std::to_string(h.height) +
         " is too large");
  }
  if (!seen.points) h.points = wh;
  if (wh != h.points) {
    fail("POINTS is " + std::to_string(h.points) + " but WIDTH x HEIGHT is " +
         std::to_string(h.width) + " x " + std::to_string(h.height));
  }
}

Layout Parser::layout_of(const Header& h) const {
  Layout l;
  std::array<std::optional<std::size_t>, 3> xyz;
  std::string names;
  for (std::size_t i = 0; i < h.fields.size(); ++i) {
    const Field& f = h.fields[i];
    names += (names.empty() ? "" : " ") + f.name;
    l.byte_offset.push_back(l.point_size);
    l.value_offset.push_back(l.values_per_point);
    l.point_size += f.size * f.count;
    l.values_per_point += f.count;
    for (std::size_t a = 0; a < 3; ++a) {
      if (f.name != std::string(1, static_cast<char>('x' + a))) continue;
      if (xyz[a]) fail("field '" + f.name + "' appears twice");
      if (f.type != 'F' || f.count != 1) {
        fail("field '" + f.name + "' must be TYPE F with SIZE 4 or 8 and COUNT 1");
      }
      xyz[a] = i;
    }
    if ((f.name == "rgb" || f.name == "rgba") && !l.rgb) {
      if (f.size != 4 || f.count != 1) {
        fail("field '" + f.name + "' must have SIZE 4 and COUNT 1 (packed 0x00RRGGBB)");
      }
      l.rgb = i;
    }
  }
  for (std::size_t a = 0; a < 3; ++a) {
    if (!xyz[a]) {
      fail("there is no '" + std::string(1, static_cast<char>('x' + a)) +
           "' field (FIELDS: " + names + ")");
    }
    l.xyz[a] = *xyz[a];
  }
  return l;
}

// One point from its fields' bytes; `at(field)` gives where a field's value starts.
template <typename At>
void take_point(const Header& h, const Layout& l, At at, PointCloud& cloud, std::size_t& dropped) {
  Eigen::Vector3f p;
  for (std::size_t a = 0; a < 3; ++a) {
    const std::size_t f = l.xyz[a];
    p[a] =
        h.fields[f].size == 4 ? load_le<float>(at(f)) : static_cast<float>(load_le<double>(at(f)));
  }
  if (!p.allFinite()) {
    ++dropped;
    return;
  }
  cloud.points.push_back(p);
  if (l.rgb) cloud.colors.push_back(unpack_rgb(load_le<std::uint32_t>(at(*l.rgb))));
}

void Parser::read_binary(const Header& h, const Layout& l, PointCloud& cloud,
                         std::size_t& dropped) {
  const std::size_t remaining = bytes_.size() - pos_;
  // Checked before reserving, so a header that lies about the count cannot make us allocate.
  if (h.points > remaining / l.point_size) {
    fail("the header declares " + std::to_string(h.points) + " points of " +
         std::to_string(l.point_size) + " bytes but only " + std::to_string(remaining) +
         " bytes of data follow (the file is truncated or the count is wrong)");
  }
  const auto n = static_cast<std::size_t>(h.points);
  cloud.points.reserve(n);
  if (l.rgb) cloud.colors.reserve(n);
  const char* base = bytes_.data() + pos_;
  for (std::size_t i = 0; i < n; ++i) {
    const char* point = base + i * l.point_size;
    take_point(
        h, l, [&](std::size_t f) { return point + l.byte_offset[f]; }, cloud, dropped);
  }
}

void Parser::read_compressed(const Header& h, const Layout& l, PointCloud& cloud,
                             std::size_t& dropped) {
  if (h.points == 0) return;
  const std::size_t remaining = bytes_.size() - pos_;
  if (remaining < 8) fail("the data ends before the compressed block's sizes");
  const auto compressed = load_le<std::uint32_t>(bytes_.data() + pos_);
  const auto uncompressed = load_le<std::uint32_t>(bytes_.data() + pos_ + 4);
  if (compressed > remaining - 8) {
    fail("the compressed block claims " + std::to_string(compressed) + " bytes but only " +
         std::to_string(remaining - 8) + " follow (the file is truncated)");
  }
  // Compressed bodies store each field for all points in turn (x x x ... y y y ...), and
  // leave out the padding fields named "_", as PCL writes them.
  std::size_t packed_size = 0;
  for (const Field& f : h.fields) {
    if (f.name != "_") packed_size += f.size * f.count;
  }
  if (h.points > std::numeric_limits<std::uint32_t>::max() / packed_size ||
      h.points * packed_size != uncompressed) {
    fail("the header declares " + std::to_string(h.points) + " points of " +
         std::to_string(packed_size) + " bytes (without padding) but the compressed block " +
         "unpacks to " + std::to_string(uncompressed) + " bytes");
  }
  if (uncompressed > kMaxLzfRatio * compressed) {
    fail("the compressed block of " + std::to_string(compressed) + " bytes cannot unpack to the " +
         std::to_string(uncompressed) +
         " bytes the header declares (the file is truncated or the count is wrong)");
  }
  std::vector<char> raw(uncompressed);
  if (!lzf_decompress(bytes_.substr(pos_ + 8, compressed), raw)) {
    fail("the compressed block is corrupt (LZF decompression failed)");
  }
  const auto n = static_cast<std::size_t>(h.points);
  std::vector<const char*> column(h.fields.size(), nullptr);
  std::size_t offset = 0;
  for (std::size_t f = 0; f < h.fields.size(); ++f) {
    if (h.fields[f].name == "_") continue;
    column[f] = raw.data() + offset;
    offset += n * h.fields[f].size * h.fields[f].count;
  }
  cloud.points.reserve(n);
  if (l.rgb) cloud.colors.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    take_point(
        h, l, [&](std::size_t f) { return column[f] + i * h.fields[f].size * h.fields[f].count; },
        cloud, dropped);
  }
}

void Parser::read_ascii(const Header& h, const Layout& l, PointCloud& cloud, std::size_t& dropped) {
  // Every value takes at least one character and one separator.
  const std::size_t remaining = bytes_.size() - pos_;
  if (h.points > (remaining + 1) / (2 * l.values_per_point)) {
    fail("the header declares " + std::to_string(h.points) + " points but only " +
         std::to_string(remaining) +
         " bytes of data follow (the file is truncated or the count is wrong)");
  }
  const auto n = static_cast<std::size_t>(h.points);
  cloud.points.reserve(n);
  if (l.rgb) cloud.colors.reserve(n);
  std::string_view line;
  for (std::size_t i = 0; i < n;) {
    if (!next_line(line)) {
      fail("the data ends after " + std::to_string(i) + " of " + std::to_string(n) +
           " points (the file is truncated or the count is wrong)");
    }
    const auto tok = text_scan::split_ws(line);
    if (tok.empty()) continue;
    if (tok.size() != l.values_per_point) {
      fail_line(line_, "point " + std::to_string(i) + " has " + std::to_string(tok.size()) +
                           " values but the header's fields need " +
                           std::to_string(l.values_per_point));
    }
    ++i;
    Eigen::Vector3f p;
    for (std::size_t a = 0; a < 3; ++a) {
      const std::string_view v = tok[l.value_offset[l.xyz[a]]];
      double d = 0;
      if (!text_scan::parse_double(v, d)) {
        fail_line(line_, "field '" + h.fields[l.xyz[a]].name + "': '" +
                             std::string(v.substr(0, 40)) + "' is not a number");
      }
      p[a] = static_cast<float>(d);
    }
    Rgb rgb{};
    if (l.rgb) {
      const std::string_view v = tok[l.value_offset[*l.rgb]];
      std::uint32_t bits = 0;
      if (!parse_rgb_token(v, h.fields[*l.rgb].type, bits)) {
        fail_line(line_, "field '" + h.fields[*l.rgb].name + "': '" + std::string(v.substr(0, 40)) +
                             "' is not a packed colour");
      }
      rgb = unpack_rgb(bits);
    }
    if (!p.allFinite()) {
      ++dropped;
      continue;
    }
    cloud.points.push_back(p);
    if (l.rgb) cloud.colors.push_back(rgb);
  }
  while (next_line(line)) {
    if (!text_scan::split_ws(line).empty()) {
      fail_line(line_, "more point lines than the header's POINTS " + std::to_string(n));
    }
  }
}

PointCloud Parser::parse(PcdInfo* info) {
  const Header h = parse_header();
  const Layout l = layout_of(h);
  PointCloud cloud;
  std::size_t dropped = 0;
  switch (h.data) {
    case PcdData::kAscii:
      read_ascii(h, l, cloud, dropped);
      break;
    case PcdData::kBinary:
      read_binary(h, l, cloud, dropped);
      break;
    case PcdData::kBinaryCompressed:
      read_compressed(h, l, cloud, dropped);
      break;
  }
  if (info) {
    info->data = h.data;
    info->width = static_cast<std::size_t>(h.width);
    info->height = static_cast<std::size_t>(h.height);
    info->declared_points = static_cast<std::size_t>(h.points);
    info->viewpoint = h.viewpoint;
    info->dropped_non_finite = dropped;
  }
  return cloud;
}

}  // namespace

PointCloud read_pcd_bytes(std::string_view bytes, const std::string& source_name, PcdInfo* info) {
  return Parser(bytes, source_name).parse(info);
}

PointCloud read_pcd(const std::filesystem::path& file, PcdInfo* info) {
  const std::string bytes = read_scan_file_bytes(file);
  return read_pcd_bytes(bytes, file.string(), info);
}

std::string write_pcd_bytes(const PointCloud& cloud, bool binary) {
  const bool colors = cloud.has_colors();
  const std::string n = std::to_string(cloud.size());
  std::string out = "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\n";
  out += colors ? "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
                : "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  out += "WIDTH " + n + "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + n + "\n";
  out += binary ? "DATA binary\n" : "DATA ascii\n";
  out.reserve(out.size() + cloud.size() * (binary ? 16 : 48));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& p = cloud.points[i];
    std::uint32_t bits = 0;
    if (colors) {
      const Rgb& c = cloud.colors[i];
      bits = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
    }
    if (binary) {
      append_le(out, p.x());
      append_le(out, p.y());
      append_le(out, p.z());
      if (colors) append_le(out, bits);
      continue;
    }
    text_scan::append_text(out, p.x());
    out += ' ';
    text_scan::append_text(out, p.y());
    out += ' ';
    text_scan::append_text(out, p.z());
    // The colour as the integer, as PCL writes it: as a float it can be NaN or denormal.
    if (colors) out += ' ' + std::to_string(bits);
    out += '\n';
  }
  return out;
}

void write_pcd(const std::filesystem::path& file, const PointCloud& cloud, bool binary) {
  write_scan_file_bytes(file, write_pcd_bytes(cloud, binary));
}

}  // namespace scanplan

#include "scanplan/io/scan_file.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <system_error>

#include "scanplan/io/pcd_io.hpp"
#include "scanplan/io/ply_io.hpp"
#include "scanplan/io/threedtk.hpp"

namespace scanplan {
namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

// The first bytes of unrecognised data, printable, so a person can see what was sent instead.
std::string preview(std::string_view bytes) {
  std::string out;
  for (const char c : bytes.substr(0, 24)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 32 && u < 127) {
      out += c;
    } else {
      static constexpr char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    }
  }
  return out;
}

}  // namespace

std::string read_scan_file_bytes(const std::filesystem::path& file) {
  std::error_code ec;
  const auto status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) throw ScanFileError(file.string() + ": no such file");
  if (!std::filesystem::is_regular_file(status)) {
    throw ScanFileError(file.string() + ": not a regular file");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ScanFileError(file.string() + ": cannot open: " + std::strerror(errno));
  const auto size = std::filesystem::file_size(file, ec);
  if (ec) throw ScanFileError(file.string() + ": cannot get its size: " + ec.message());
  std::string bytes(static_cast<std::size_t>(size), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<std::uintmax_t>(in.gcount()) != size) {
    throw ScanFileError(file.string() + ": read error (the file shrank while being read?)");
  }
  return bytes;
}

void write_scan_file_bytes(const std::filesystem::path& file, std::string_view bytes) {
  std::filesystem::path part = file;
  part += ".part";
  {
    std::ofstream out(part, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw ScanFileError(file.string() + ": cannot create " + part.string() + ": " +
                          std::strerror(errno));
    }
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    out.close();
    if (!out) {
      const std::string why = std::strerror(errno);
      std::error_code ignored;
      std::filesystem::remove(part, ignored);
      throw ScanFileError(file.string() + ": write failed: " + why);
    }
  }
  std::error_code ec;
  std::filesystem::rename(part, file, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(part, ignored);
    throw ScanFileError(file.string() + ": cannot rename " + part.string() +
                        " into place: " + ec.message());
  }
}

PointCloud read_point_cloud(const std::filesystem::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".ply") return read_ply(file);
  if (ext == ".pcd") return read_pcd(file);
  if (ext == ".3d") return read_threedtk_scan(file);
  throw ScanFileError(file.string() + ": unsupported point-cloud file type '" + ext +
                      "' (expected .ply, .pcd or .3d)");
}

PointCloud read_point_cloud_bytes(std::string_view bytes, const std::string& source_name) {
  auto starts = [&](std::string_view prefix) { return bytes.substr(0, prefix.size()) == prefix; };
  if (starts("ply\n") || starts("ply\r\n")) return read_ply_bytes(bytes, source_name);
  if (starts("# .PCD") || starts("VERSION") || starts("FIELDS")) {
    return read_pcd_bytes(bytes, source_name);
  }
  if (bytes.empty()) throw ScanFileError(source_name + ": is empty (expected a PLY or PCD file)");
  throw ScanFileError(source_name + ": not a PLY or PCD file (it starts with \"" + preview(bytes) +
                      "\")");
}

}  // namespace scanplan

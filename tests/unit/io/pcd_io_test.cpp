#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <string>
#include <string_view>

#include "scan_file_test_support.hpp"
#include "scanplan/io/pcd_io.hpp"
#include "scanplan/io/ply_io.hpp"
#include "scanplan/io/scan_file.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;
using test_support::expect_error;
using test_support::expect_same;
using test_support::little_endian;
using test_support::TempDir;

PointCloud sample_cloud(bool colors, std::size_t n = 5) {
  PointCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.points.emplace_back(0.5f * static_cast<float>(i), -1.25f + static_cast<float>(i * i),
                          1e-3f * static_cast<float>(i) - 7.0f);
    if (colors) {
      c.colors.push_back(Rgb{static_cast<std::uint8_t>(255 - i), static_cast<std::uint8_t>(i * 40),
                             static_cast<std::uint8_t>(i % 2 ? 255 : 0)});
    }
  }
  return c;
}

void expect_bytes_error(const std::string& bytes, std::initializer_list<std::string> fragments) {
  expect_error([&] { read_pcd_bytes(bytes, "in.pcd"); }, fragments);
}

// A plain greedy LZF compressor, only to make test input for the reader's decompressor.
std::string lzf_compress(std::string_view in) {
  std::string out, literal;
  auto flush = [&] {
    while (!literal.empty()) {
      const std::size_t n = std::min<std::size_t>(literal.size(), 32);
      out += static_cast<char>(n - 1);
      out += literal.substr(0, n);
      literal.erase(0, n);
    }
  };
  for (std::size_t i = 0; i < in.size();) {
    std::size_t best_len = 0, best_back = 0;
    for (std::size_t back = 1; back <= std::min<std::size_t>(i, 8192); ++back) {
      std::size_t len = 0;
      while (i + len < in.size() && len < 264 && in[i + len] == in[i + len - back]) ++len;
      if (len > best_len) {
        best_len = len;
        best_back = back;
      }
    }
    if (best_len < 3) {
      literal += in[i++];
      continue;
    }
    flush();
    const std::size_t len = best_len - 2, off = best_back - 1;
    if (len < 7) {
      out += static_cast<char>((len << 5) | (off >> 8));
    } else {
      out += static_cast<char>((7 << 5) | (off >> 8));
      out += static_cast<char>(len - 7);
    }
    out += static_cast<char>(off & 0xff);
    i += best_len;
  }
  flush();
  return out;
}

std::string compressed_body(const std::string& raw, const std::string& lzf) {
  return little_endian(static_cast<std::uint32_t>(lzf.size())) +
         little_endian(static_cast<std::uint32_t>(raw.size())) + lzf;
}

TEST(PcdIo, RoundTripsAsciiAndBinaryWithAndWithoutColour) {
  for (const bool binary : {false, true}) {
    for (const bool colors : {false, true}) {
      SCOPED_TRACE(testing::Message() << "binary " << binary << " colours " << colors);
      const PointCloud cloud = sample_cloud(colors);
      PcdInfo info;
      const PointCloud back = read_pcd_bytes(write_pcd_bytes(cloud, binary), "mem.pcd", &info);
      expect_same(cloud, back);
      EXPECT_EQ(info.data, binary ? PcdData::kBinary : PcdData::kAscii);
      EXPECT_EQ(info.width, cloud.size());
      EXPECT_EQ(info.height, 1u);
      EXPECT_EQ(info.declared_points, cloud.size());
    }
  }
}

TEST(PcdIo, WritesRgbAsPclDoes) {
  PointCloud c;
  c.push_back(Eigen::Vector3f(1, 2, 3), Rgb{0x12, 0x34, 0x56});
  const std::string bin = write_pcd_bytes(c, true);
  EXPECT_NE(bin.find("FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 1\n"
                     "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\nDATA binary\n"),
            std::string::npos);
  EXPECT_EQ(bin.substr(bin.size() - 4), little_endian(std::uint32_t{0x123456}));
  const std::string ascii = write_pcd_bytes(c, false);
  EXPECT_EQ(ascii.substr(ascii.find("DATA ascii\n") + 11), "1 2 3 1193046\n");  // 0x123456
}

TEST(PcdIo, FileRoundTripAndMissingFile) {
  TempDir dir;
  const PointCloud cloud = sample_cloud(true, 100);
  write_pcd(dir.path() / "a.pcd", cloud);
  expect_same(cloud, read_pcd(dir.path() / "a.pcd"));
  expect_error([&] { read_pcd(dir.path() / "b.pcd"); }, {"b.pcd", "no such file"});
}

TEST(PcdIo, ReadsAsciiRgbInAllThreeSpellings) {
  const std::uint32_t bits = 0x00ff8001;
  float as_float = 0;
  std::memcpy(&as_float, &bits, sizeof bits);
  std::array<char, 64> text{};
  const auto end = std::to_chars(text.data(), text.data() + text.size(), as_float).ptr;
  const std::string old_style(text.data(), end);  // a denormal such as 2.3509e-38

  const std::string head_f =
      "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\n"
      "SIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\n"
      "VIEWPOINT 1 2 3 1 0 0 0\nPOINTS 2\nDATA ascii\n";
  PcdInfo info;
  const PointCloud f =
      read_pcd_bytes(head_f + "1 2 3 16744449\n4 5 6 " + old_style + "\n", "f.pcd", &info);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f.colors[0], (Rgb{0xff, 0x80, 0x01}));
  EXPECT_EQ(f.colors[1], (Rgb{0xff, 0x80, 0x01}));
  EXPECT_EQ(f.points[1], Eigen::Vector3f(4, 5, 6));
  EXPECT_EQ(info.viewpoint, (std::array<double, 7>{1, 2, 3, 1, 0, 0, 0}));

  // rgba as U4 0xAARRGGBB: the alpha byte is not part of the colour.
  const std::string head_u = "FIELDS x y z rgba\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH 1\nDATA ascii\n";
  EXPECT_EQ(read_pcd_bytes(head_u + "1 2 3 4278194208\n", "u.pcd").colors,  // 0xff001020
            (std::vector<Rgb>{{0x00, 0x10, 0x20}}));
}

TEST(PcdIo, ReadsDoublesAndSkipsOtherFieldsInBinary) {
  std::string bytes =
      "VERSION .7\nFIELDS _ x y z rgba histogram\nSIZE 1 8 8 8 4 4\nTYPE U F F F U F\n"
      "COUNT 3 1 1 1 1 4\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA binary\n";
  for (int i = 0; i < 2; ++i) {
    bytes += std::string(3, '\x7f');
    bytes += little_endian(1.0 + i) + little_endian(-2.0 * i) + little_endian(1e-3);
    bytes += little_endian(std::uint32_t{0xff102030} + static_cast<std::uint32_t>(i));
    for (int k = 0; k < 4; ++k) bytes += little_endian(static_cast<float>(k));
  }
  const PointCloud c = read_pcd_bytes(bytes, "d.pcd");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[1], Eigen::Vector3f(2, -2, 1e-3f));
  EXPECT_EQ(c.colors[1], (Rgb{0x10, 0x20, 0x31}));
}

TEST(PcdIo, DropsNaNPointsOfAnOrganizedCloud) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::string bytes =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 2\nDATA binary\n";
  for (const float x : {1.0f, nan, 3.0f, 4.0f}) {
    bytes += little_endian(x) + little_endian(0.0f) + little_endian(0.0f);
  }
  PcdInfo info;
  const PointCloud c = read_pcd_bytes(bytes, "org.pcd", &info);
  ASSERT_EQ(c.size(), 3u);
  EXPECT_EQ(c.points[1].x(), 3.0f);
  EXPECT_EQ(info.dropped_non_finite, 1u);
  EXPECT_EQ(info.width, 2u);
  EXPECT_EQ(info.height, 2u);
  EXPECT_EQ(info.declared_points, 4u);

  const std::string ascii =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nDATA ascii\nnan nan nan\n1 2 3\n\n4 5 inf\n";
  EXPECT_EQ(read_pcd_bytes(ascii, "a.pcd", &info).size(), 1u);
  EXPECT_EQ(info.dropped_non_finite, 2u);
}

TEST(PcdIo, ReadsBinaryCompressedColumnsWithoutPadding) {
  // PCL's layout: each field's values for all points in turn; "_" padding is not stored.
  const PointCloud cloud = sample_cloud(true, 300);
  const std::size_t n = cloud.size();
  std::string raw;
  for (int a = 0; a < 3; ++a) {
    for (std::size_t i = 0; i < n; ++i) raw += little_endian(cloud.points[i][a]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    const Rgb& c = cloud.colors[i];
    raw += little_endian((std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2]);
  }
  for (std::size_t i = 0; i < n; ++i) raw += little_endian(static_cast<float>(i % 7));  // intensity
  const std::string lzf = lzf_compress(raw);
  ASSERT_LT(lzf.size(), raw.size());  // the stream really uses back references
  const std::string bytes =
      "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z _ rgb intensity\nSIZE 4 4 4 1 4 4\n"
      "TYPE F F F U F F\nCOUNT 1 1 1 4 1 1\nWIDTH 300\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\n"
      "POINTS 300\nDATA binary_compressed\n" +
      compressed_body(raw, lzf);
  PcdInfo info;
  expect_same(cloud, read_pcd_bytes(bytes, "c.pcd", &info));
  EXPECT_EQ(info.data, PcdData::kBinaryCompressed);
}

TEST(PcdIo, DecodesAHandWrittenLzfBackReference) {
  // Two points (1, 1, 1): 24 bytes, one float repeated six times. LZF: a literal run of
  // 4 bytes (control 3), then a back reference 4 bytes back (offset byte 3) of 20 bytes
  // (length 20 - 2 = 18 = 7 + 11, so control 0xe0 and an extra length byte 11).
  // (Appended piecewise: g++ 12 warns falsely about "literal" + std::string here.)
  std::string lzf = "\x03";
  lzf += little_endian(1.0f);
  lzf += "\xe0\x0b\x03";
  const std::string bytes =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\n"
      "DATA binary_compressed\n" +
      little_endian(std::uint32_t{8}) + little_endian(std::uint32_t{24}) + lzf;
  const PointCloud c = read_pcd_bytes(bytes, "hand.pcd");
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1, 1, 1));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(1, 1, 1));
}

TEST(PcdIo, BadCompressedBlocksAreRejectedBeforeAllocating) {
  const std::string head =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 100000000\nDATA binary_compressed\n";
  expect_bytes_error(head + little_endian(std::uint32_t{10}) +
                         little_endian(std::uint32_t{1200000000}) + std::string(10, '\0'),
                     {"in.pcd", "10 bytes cannot unpack to the 1200000000 bytes"});
  const std::string two = "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nDATA binary_compressed\n";
  expect_bytes_error(two + little_endian(std::uint32_t{8}) + little_endian(std::uint32_t{20}) +
                         std::string(8, '\0'),
                     {"unpacks to 20 bytes"});
  expect_bytes_error(two + little_endian(std::uint32_t{800}) + little_endian(std::uint32_t{24}) +
                         std::string(8, '\0'),
                     {"claims 800 bytes", "truncated"});
  expect_bytes_error(two + "\x08\x00", {"ends before the compressed block"});
  // A back reference before the start of the output.
  expect_bytes_error(
      two + little_endian(std::uint32_t{3}) + little_endian(std::uint32_t{24}) + "\xe0\x0b\x03",
      {"corrupt"});
  // A stream that stops short of the declared size.
  expect_bytes_error(two + little_endian(std::uint32_t{5}) + little_endian(std::uint32_t{24}) +
                         "\x03" + little_endian(1.0f),
                     {"corrupt"});
}

TEST(PcdIo, TruncatedDataAndLyingCountsFail) {
  const std::string bin = write_pcd_bytes(sample_cloud(true), true);
  expect_bytes_error(bin.substr(0, bin.size() - 3), {"5 points of 16 bytes", "truncated"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 999999999\nDATA binary\n" +
                         std::string(10, '\0'),
                     {"999999999 points", "only 10 bytes", "truncated"});
  expect_bytes_error(
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nPOINTS 4611686018427387904\n"
      "DATA ascii\n1 2 3\n",
      {"4611686018427387904 points", "truncated"});
  const std::string ascii = write_pcd_bytes(sample_cloud(false), false);
  expect_bytes_error(ascii.substr(0, ascii.rfind('\n', ascii.size() - 2) + 1),
                     {"ends after 4 of 5 points"});
  expect_bytes_error(ascii + "1 2 3\n", {"line 17", "more point lines than the header's POINTS"});
}

TEST(PcdIo, HeaderErrorsNameTheProblem) {
  expect_bytes_error("FIELDS y z\nSIZE 4 4\nTYPE F F\nWIDTH 0\nDATA ascii\n",
                     {"in.pcd", "no 'x' field", "FIELDS: y z"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 4\nTYPE U F F\nWIDTH 0\nDATA ascii\n",
                     {"'x' must be TYPE F"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 0\nDATA ascii\n",
                     {"SIZE has 2 entries but FIELDS has 3"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 3\nTYPE F F F\nWIDTH 0\nDATA ascii\n",
                     {"line 2", "SIZE '3'"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 2\nTYPE F F F\nWIDTH 0\nDATA ascii\n",
                     {"'z' has TYPE F with SIZE 2"});
  expect_bytes_error("FIELDS x y z rgb\nSIZE 4 4 4 1\nTYPE F F F U\nWIDTH 0\nDATA ascii\n",
                     {"'rgb' must have SIZE 4"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 0\nDATA lzma\n",
                     {"line 5", "unknown DATA 'lzma'"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\n", {"no 'DATA' line"});
  expect_bytes_error(
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 2\nHEIGHT 2\nPOINTS 5\nDATA ascii\n",
      {"POINTS is 5 but WIDTH x HEIGHT is 2 x 2"});
  expect_bytes_error("FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 99999999\nWIDTH 0\n",
                     {"line 4", "COUNT '99999999'"});
  expect_bytes_error("FIELDS x y z\nFIELDS x y z\n", {"line 2", "a second 'FIELDS' line"});
  expect_bytes_error("\x89PNG\r\n", {"line 1", "unexpected header line"});
}

TEST(PcdIo, AsciiValueErrorsNameTheLine) {
  const std::string head = "FIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nWIDTH 2\nDATA ascii\n";
  expect_bytes_error(head + "1 2 3 0\n1 2 z 0\n", {"line 7", "field 'z': 'z' is not a number"});
  expect_bytes_error(head + "1.5 2.5 3.5\n1 2 3 4\n", {"line 6", "has 3 values", "need 4"});
  expect_bytes_error(head + "1 2 3 -1\n1 2 3 4\n", {"line 6", "not a packed colour"});
}

TEST(ScanFile, SniffsPlyAndPcdBytes) {
  const PointCloud cloud = sample_cloud(true);
  expect_same(cloud, read_point_cloud_bytes(write_ply_bytes(cloud), "body"));
  expect_same(cloud, read_point_cloud_bytes(write_pcd_bytes(cloud), "body"));
  const std::string pcd = write_pcd_bytes(cloud, false);
  const std::string from_version = pcd.substr(pcd.find("VERSION"));
  const std::string from_fields = pcd.substr(pcd.find("FIELDS"));
  expect_same(cloud, read_point_cloud_bytes(from_version, "body"));
  expect_same(cloud, read_point_cloud_bytes(from_fields, "body"));
  expect_error([] { read_point_cloud_bytes("\x89PNG\r\n\x1a\n", "upload"); },
               {"upload", "not a PLY or PCD file", "\\x89PNG\\x0d\\x0a"});
  expect_error([] { read_point_cloud_bytes("", "upload"); }, {"upload", "is empty"});
  // Sniffed as PLY, so the PLY reader's own message comes through.
  expect_error([] { read_point_cloud_bytes("ply\nformat ascii 1.0\n", "upload"); },
               {"upload", "end_header"});
}

TEST(ScanFile, DispatchesOnExtension) {
  TempDir dir;
  const PointCloud cloud = sample_cloud(false);
  write_ply(dir.path() / "a.ply", cloud);
  write_pcd(dir.path() / "b.PCD", cloud);
  expect_same(cloud, read_point_cloud(dir.path() / "a.ply"));
  expect_same(cloud, read_point_cloud(dir.path() / "b.PCD"));
  dir.write("c.3d", "100 0 0\n0 0 0\n");
  const PointCloud t = read_point_cloud(dir.path() / "c.3d");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_TRUE(t.points[0].isApprox(Eigen::Vector3f(0, -1, 0)));
  write_ply(dir.path() / "d.xyz", cloud);
  expect_error([&] { read_point_cloud(dir.path() / "d.xyz"); },
               {"d.xyz", "unsupported", "'.xyz'", ".ply, .pcd or .3d"});
  expect_error([&] { read_point_cloud(dir.path() / "e.ply"); }, {"e.ply", "no such file"});
  fs::create_directory(dir.path() / "f.ply");
  expect_error([&] { read_point_cloud(dir.path() / "f.ply"); }, {"f.ply", "not a regular file"});
}

}  // namespace
}  // namespace scanplan

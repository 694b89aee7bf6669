#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <string>

#include "scan_file_test_support.hpp"
#include "scanplan/io/ply_io.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;
using test_support::big_endian;
using test_support::expect_error;
using test_support::expect_same;
using test_support::little_endian;
using test_support::TempDir;

PointCloud sample_cloud(bool colors) {
  PointCloud c;
  const std::array<Eigen::Vector3f, 4> pts{Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(1.5f, -2, 3),
                                           Eigen::Vector3f(0.1f, 1e-7f, -123456.78f),
                                           Eigen::Vector3f(-0.3f, 7.25f, 1e30f)};
  for (std::size_t i = 0; i < pts.size(); ++i) {
    c.points.push_back(pts[i]);
    if (colors) {
      c.colors.push_back(Rgb{static_cast<std::uint8_t>(i * 80), static_cast<std::uint8_t>(255 - i),
                             static_cast<std::uint8_t>(i)});
    }
  }
  return c;
}

void expect_bytes_error(const std::string& bytes, std::initializer_list<std::string> fragments) {
  expect_error([&] { read_ply_bytes(bytes, "in.ply"); }, fragments);
}

TEST(PlyIo, RoundTripsInEveryFormatWithAndWithoutColour) {
  for (const PlyFormat format :
       {PlyFormat::kAscii, PlyFormat::kBinaryLittleEndian, PlyFormat::kBinaryBigEndian}) {
    for (const bool colors : {false, true}) {
      SCOPED_TRACE(testing::Message()
                   << "format " << static_cast<int>(format) << " colours " << colors);
      const PointCloud cloud = sample_cloud(colors);
      const std::string bytes = write_ply_bytes(cloud, {"pose 1 2 3", ""}, format);
      PlyInfo info;
      const PointCloud back = read_ply_bytes(bytes, "mem.ply", &info);
      expect_same(cloud, back);
      EXPECT_EQ(back.has_colors(), colors);
      EXPECT_EQ(info.format, format);
      EXPECT_EQ(info.vertex_count, cloud.size());
      EXPECT_EQ(info.dropped_non_finite, 0u);
      EXPECT_EQ(info.comments, (std::vector<std::string>{"pose 1 2 3", ""}));
    }
  }
}

TEST(PlyIo, WritesTheDocumentedHeader) {
  const std::string bytes = write_ply_bytes(sample_cloud(true), {"true_pose 1 2 0 90"});
  const std::string header = bytes.substr(0, bytes.find("end_header\n") + 11);
  EXPECT_EQ(header,
            "ply\nformat binary_little_endian 1.0\ncomment true_pose 1 2 0 90\n"
            "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
            "property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n");
  EXPECT_EQ(bytes.size(), header.size() + 4 * 15);
}

TEST(PlyIo, WriteRejectsACommentWithALineBreak) {
  EXPECT_THROW(write_ply_bytes(sample_cloud(false), {"two\nlines"}), std::invalid_argument);
}

TEST(PlyIo, FileRoundTripAndMissingFile) {
  TempDir dir;
  const fs::path file = dir.path() / "scan.ply";
  const PointCloud cloud = sample_cloud(true);
  write_ply(file, cloud, {"hello"});
  EXPECT_FALSE(fs::exists(dir.path() / "scan.ply.part"));
  PlyInfo info;
  expect_same(cloud, read_ply(file, &info));
  EXPECT_EQ(info.comments, std::vector<std::string>{"hello"});
  expect_error([&] { read_ply(dir.path() / "nope.ply"); }, {"nope.ply", "no such file"});
}

TEST(PlyIo, ReadsAHandMadeBigEndianFileWithSkippedProperties) {
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\ncomment made by hand\nobj_info scanner X\n"
      "element vertex 2\nproperty double x\nproperty float32 y\nproperty float z\n"
      "property ushort intensity\nproperty uchar red\nproperty uint8 green\n"
      "property uchar blue\nproperty list uchar int extra\nend_header\n";
  bytes += big_endian(1.5) + big_endian(-2.25f) + big_endian(3.0f) +
           big_endian(std::uint16_t{0x1234}) + "\x0a\x14\x1e" + big_endian(std::uint8_t{2}) +
           big_endian(std::int32_t{7}) + big_endian(std::int32_t{-8});
  bytes += big_endian(4.0) + big_endian(5.0f) + big_endian(6.0f) +
           big_endian(std::uint16_t{0xffff}) + "\x28\x32\x3c" + big_endian(std::uint8_t{0});
  PlyInfo info;
  const PointCloud c = read_ply_bytes(bytes, "be.ply", &info);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(1.5f, -2.25f, 3.0f));
  EXPECT_EQ(c.points[1], Eigen::Vector3f(4, 5, 6));
  ASSERT_TRUE(c.has_colors());
  EXPECT_EQ(c.colors[0], (Rgb{10, 20, 30}));
  EXPECT_EQ(c.colors[1], (Rgb{40, 50, 60}));
  EXPECT_EQ(info.format, PlyFormat::kBinaryBigEndian);
  EXPECT_EQ(info.comments, std::vector<std::string>{"made by hand"});
  EXPECT_EQ(info.obj_info, std::vector<std::string>{"scanner X"});
}

TEST(PlyIo, SkipsElementsBeforeAndAfterTheVertices) {
  std::string bin =
      "ply\nformat binary_little_endian 1.0\nelement face 2\n"
      "property list uchar int vertex_indices\nproperty float quality\n"
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\n"
      "element edge 1\nproperty int a\nend_header\n";
  bin += little_endian(std::uint8_t{3}) + little_endian(0) + little_endian(1) + little_endian(2) +
         little_endian(0.5f);
  bin += little_endian(std::uint8_t{0}) + little_endian(0.25f);
  bin += little_endian(7.0f) + little_endian(8.0f) + little_endian(9.0f);
  bin += little_endian(42);
  const PointCloud c = read_ply_bytes(bin, "faces.ply");
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c.points[0], Eigen::Vector3f(7, 8, 9));
  EXPECT_FALSE(c.has_colors());

  // CRLF line ends, as Windows tools write them.
  const std::string ascii =
      "ply\r\nformat ascii 1.0\r\nelement material 1\r\nproperty uchar shine\r\n"
      "element vertex 2\r\nproperty float x\r\nproperty float y\r\nproperty float z\r\n"
      "property list uchar float normals\r\nelement face 1\r\n"
      "property list uchar int vertex_indices\r\nend_header\r\n"
      "12\r\n1 2 3 0\r\n\r\n-4 5e-1 +6 2 0.5 0.5\r\n3 0 1 1\r\n";
  const PointCloud a = read_ply_bytes(ascii, "a.ply");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.points[1], Eigen::Vector3f(-4, 0.5f, 6));
}

TEST(PlyIo, ReadsOtherColourNames) {
  const std::string rgb =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar r\nproperty uchar g\nproperty uchar b\n"
      "property uchar alpha\nend_header\n1 2 3 4 5 6 7\n";
  EXPECT_EQ(read_ply_bytes(rgb, "rgb.ply").colors, (std::vector<Rgb>{{4, 5, 6}}));
  const std::string diffuse =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float64 x\nproperty double y\n"
      "property float z\nproperty uchar diffuse_blue\nproperty uchar diffuse_green\n"
      "property uchar diffuse_red\nend_header\n1 2 3 4 5 6\n";
  EXPECT_EQ(read_ply_bytes(diffuse, "d.ply").colors, (std::vector<Rgb>{{6, 5, 4}}));
}

TEST(PlyIo, DropsNonFinitePointsAndCountsThem) {
  PointCloud cloud = sample_cloud(true);
  cloud.points[1].y() = std::numeric_limits<float>::quiet_NaN();
  cloud.points[2].z() = std::numeric_limits<float>::infinity();
  for (const PlyFormat format : {PlyFormat::kAscii, PlyFormat::kBinaryLittleEndian}) {
    PlyInfo info;
    const PointCloud back = read_ply_bytes(write_ply_bytes(cloud, {}, format), "nan.ply", &info);
    ASSERT_EQ(back.size(), 2u);
    EXPECT_EQ(back.points[0], cloud.points[0]);
    EXPECT_EQ(back.points[1], cloud.points[3]);
    EXPECT_EQ(back.colors[1], cloud.colors[3]);
    EXPECT_EQ(info.vertex_count, 4u);
    EXPECT_EQ(info.dropped_non_finite, 2u);
  }
  // A double too large for a float is no usable point either.
  const std::string big =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
      "property double z\nend_header\n1e300 0 0\n1 2 1e999\n";
  PlyInfo info;
  EXPECT_TRUE(read_ply_bytes(big, "big.ply", &info).empty());
  EXPECT_EQ(info.dropped_non_finite, 2u);
}

TEST(PlyIo, TruncatedDataAndLyingCountsFailBeforeAllocating) {
  const std::string good = write_ply_bytes(sample_cloud(true));
  expect_bytes_error(good.substr(0, good.size() - 7), {"in.ply", "4 vertices", "truncated"});

  const std::string head =
      "ply\nformat binary_little_endian 1.0\nelement vertex 999999999\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  expect_bytes_error(head + std::string(10, '\0'),
                     {"999999999 vertices", "only 10 bytes", "truncated"});
  // Reserving this many points would throw std::length_error, not a ScanFileError.
  const std::string huge =
      "ply\nformat ascii 1.0\nelement vertex 4611686018427387904\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n1 2 3\n";
  expect_bytes_error(huge, {"4611686018427387904 vertices", "truncated"});
  expect_bytes_error(
      "ply\nformat ascii 1.0\nelement vertex 99999999999999999999999\nproperty float x\n",
      {"line 3", "not a non-negative integer"});
  expect_bytes_error("ply\nformat ascii 1.0\nelement vertex -5\n", {"line 3", "'-5'"});

  const std::string ascii = write_ply_bytes(sample_cloud(false), {}, PlyFormat::kAscii);
  expect_bytes_error(ascii.substr(0, ascii.rfind('\n', ascii.size() - 2) + 1),
                     {"ends after 3 of 4 vertices"});

  // A list whose length runs past the end of the data.
  std::string list =
      "ply\nformat binary_little_endian 1.0\nelement face 1\n"
      "property list uint int idx\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nend_header\n";
  list += little_endian(std::uint32_t{0xffffffff}) + std::string(12, '\0');
  expect_bytes_error(list, {"list of 4294967295 items"});
}

TEST(PlyIo, GarbageAndBadHeadersGiveClearMessages) {
  expect_bytes_error("\x89PNG\r\n\x1a\n....", {"in.ply", "not a PLY file"});
  expect_bytes_error("", {"not a PLY file"});
  expect_bytes_error("ply\nformat ascii 1.0\nelement vertex 1\n", {"no 'end_header'"});
  expect_bytes_error("ply\nformat text 1.0\nend_header\n", {"line 2", "unknown format 'text'"});
  expect_bytes_error("ply\nformat ascii 2.0\nend_header\n", {"version '2.0'"});
  expect_bytes_error("ply\nelement vertex 0\nend_header\n", {"no 'format' line"});
  expect_bytes_error("ply\nformat ascii 1.0\nproperty float x\nend_header\n",
                     {"line 3", "before any 'element'"});
  expect_bytes_error("ply\nformat ascii 1.0\nelement vertex 0\nproperty flaot x\nend_header\n",
                     {"line 4", "unknown property type 'flaot'"});
  expect_bytes_error("ply\nformat ascii 1.0\nelement vertex 0\nwhatever\nend_header\n",
                     {"line 4", "unexpected header line 'whatever'"});
  expect_bytes_error("ply\nformat ascii 1.0\nelement face 0\nend_header\n",
                     {"no 'vertex' element"});
}

TEST(PlyIo, MissingOrMistypedCoordinatesAreRejected) {
  const std::string missing_x =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float y\nproperty float z\n"
      "end_header\n1 2\n";
  expect_bytes_error(missing_x, {"no 'x' property", "it has: y z"});
  const std::string int_x =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty int x\nproperty float y\n"
      "property float z\nend_header\n1 2 3\n";
  expect_bytes_error(int_x, {"'x' must be a float or double"});
  const std::string list_z =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property list uchar float z\nend_header\n1 2 1 3\n";
  expect_bytes_error(list_z, {"'z' must be a float or double"});
  const std::string float_red =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty float red\nproperty float green\nproperty float blue\n"
      "end_header\n1 2 3 0.5 0.5 0.5\n";
  expect_bytes_error(float_red, {"'red' must be uchar"});
  const std::string red_only =
      "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nend_header\n1 2 3 4\n";
  expect_bytes_error(red_only, {"'green' is missing"});
}

TEST(PlyIo, AsciiValueErrorsNameTheLine) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\n"
      "property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n";
  expect_bytes_error(head + "1 2 3 4 5 6\n1 two 3 4 5 6\n",
                     {"in.ply", "line 12", "vertex 1", "'two' is not a number"});
  expect_bytes_error(head + "1 2 3 4 5 6\n1.5 2.5 3 4 5\n", {"line 12", "has 5 values"});
  expect_bytes_error(head + "1 2 3 4 5 6 7\n1 2 3 4 5 6\n", {"line 11", "has 7 values"});
  expect_bytes_error(head + "1 2 3 4 5 256\n1 2 3 4 5 6\n",
                     {"line 11", "'256' is not an integer 0-255"});
}

}  // namespace
}  // namespace scanplan

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <string>

#include "scan_file_test_support.hpp"
#include "scanplan/io/pcd_io.hpp"
#include "scanplan/io/ply_io.hpp"
#include "scanplan/io/replay_folder.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;
using test_support::expect_error;
using test_support::TempDir;

PointCloud cloud_of(float x, std::size_t n) {
  PointCloud c;
  for (std::size_t i = 0; i < n; ++i) {
    c.push_back(Eigen::Vector3f(x, static_cast<float>(i), 1),
                Rgb{1, 2, static_cast<std::uint8_t>(i)});
  }
  return c;
}

// Checks that opening `dir` as a replay folder throws a ReplayFolderError saying `fragments`.
void expect_folder_error(const fs::path& dir, std::initializer_list<std::string> fragments) {
  SCOPED_TRACE(dir.string());
  expect_error<ReplayFolderError>([&] { const ReplayFolder folder(dir); }, fragments);
}

void expect_csv_error(const std::string& csv, std::initializer_list<std::string> fragments) {
  TempDir dir;
  write_ply(dir.path() / "a.ply", cloud_of(0, 1));
  dir.write("poses.csv", csv);
  expect_folder_error(dir.path(), fragments);
}

TEST(ReplayFolder, ListsCsvScansInOrderWithPosesAndImages) {
  TempDir dir;
  write_ply(dir.path() / "b.ply", cloud_of(1, 3));
  write_pcd(dir.path() / "a.pcd", cloud_of(2, 4));
  dir.write("b.jpg", "not really a jpeg");
  dir.write("a.png", "an image of another kind is not the scan's image");
  dir.write("poses.csv", "file,x,y,z,yaw_deg\nb.ply,1,2,0,90\n\n a.pcd , 3.5 ,-1, 0.25,-45\n");
  const ReplayFolder folder(dir.path());
  ASSERT_EQ(folder.size(), 2u);

  const auto& b = folder.entry(0);
  EXPECT_EQ(b.scan, dir.path() / "b.ply");
  EXPECT_DOUBLE_EQ(b.pose.x, 1);
  EXPECT_DOUBLE_EQ(b.pose.y, 2);
  EXPECT_DOUBLE_EQ(b.pose.z, 0);
  EXPECT_NEAR(b.pose.yaw, M_PI / 2, 1e-12);
  EXPECT_EQ(b.pose.roll, 0);
  EXPECT_EQ(b.pose.pitch, 0);
  ASSERT_TRUE(b.image.has_value());
  EXPECT_EQ(*b.image, dir.path() / "b.jpg");

  const auto& a = folder.entry(1);
  EXPECT_EQ(a.scan, dir.path() / "a.pcd");
  EXPECT_DOUBLE_EQ(a.pose.x, 3.5);
  EXPECT_DOUBLE_EQ(a.pose.z, 0.25);
  EXPECT_NEAR(a.pose.yaw, -M_PI / 4, 1e-12);
  EXPECT_FALSE(a.image.has_value());

  EXPECT_EQ(folder.load(0).points, cloud_of(1, 3).points);
  EXPECT_EQ(folder.load(1).colors, cloud_of(2, 4).colors);
  EXPECT_THROW(folder.entry(2), std::out_of_range);
  EXPECT_THROW(folder.load(2), std::out_of_range);
}

TEST(ReplayFolder, AcceptsRollPitchAnyColumnOrderCrlfAndByteOrderMark) {
  TempDir dir;
  fs::create_directory(dir.path() / "scans");
  write_ply(dir.path() / "scans" / "s1.PLY", cloud_of(0, 1));
  dir.write("poses.csv",
            "\xEF\xBB\xBFpitch_deg,file,yaw_deg,x,y,z,roll_deg\r\n"
            "-2,scans/s1.PLY,10,1e1,0,0,3\r\n");
  const ReplayFolder folder(dir.path());
  ASSERT_EQ(folder.size(), 1u);
  const Pose& p = folder.entry(0).pose;
  EXPECT_DOUBLE_EQ(p.x, 10);
  EXPECT_NEAR(p.yaw, deg2rad(10), 1e-12);
  EXPECT_NEAR(p.roll, deg2rad(3), 1e-12);
  EXPECT_NEAR(p.pitch, deg2rad(-2), 1e-12);
  EXPECT_EQ(folder.entry(0).scan, dir.path() / "scans" / "s1.PLY");
}

TEST(ReplayFolder, CsvErrorsNameTheLineAndColumn) {
  expect_csv_error("file,x,y,z,yaw_deg\na.ply,1,2,3,4\nmissing.ply,1,2,3,4\n",
                   {"poses.csv line 3", "'missing.ply' does not exist"});
  expect_csv_error("file,x,y,z,yaw_deg\na.ply,1,2,3,4\na.ply,1,2,3,abc\n",
                   {"poses.csv line 3", "column 'yaw_deg'", "'abc' is not a finite number"});
  expect_csv_error("file,x,y,z,yaw_deg\na.ply,1,nan,3,4\n", {"line 2", "column 'y'", "'nan'"});
  expect_csv_error("file,x,y,z,yaw_deg\na.ply,1,2,,4\n", {"line 2", "column 'z'", "''"});
  expect_csv_error("file,x,y,z,yaw_deg,speed\na.ply,1,2,3,4,5\n",
                   {"line 1", "unknown column 'speed'"});
  expect_csv_error("file,x,y,yaw_deg\na.ply,1,2,4\n", {"line 1", "no 'z' column"});
  expect_csv_error("file,x,y,z,yaw_deg,x\n", {"line 1", "'x' appears twice"});
  expect_csv_error("file,x,y,z,yaw_deg\na.ply,1,2,3\n",
                   {"line 2", "4 values but the header has 5 columns"});
  expect_csv_error("file,x,y,z,yaw_deg\na.txt,1,2,3,4\n",
                   {"line 2", "'a.txt' is not .ply or .pcd"});
  expect_csv_error("file,x,y,z,yaw_deg\n,1,2,3,4\n", {"line 2", "'file' column is empty"});
  expect_csv_error("file,x,y,z,yaw_deg\n", {"poses.csv", "lists no scans"});
  expect_csv_error("\n\n", {"poses.csv", "is empty"});
}

TEST(ReplayFolder, ABrokenScanFailsOnlyWhenLoaded) {
  TempDir dir;
  write_ply(dir.path() / "good.ply", cloud_of(0, 2));
  dir.write("bad.ply",
            "ply\nformat binary_little_endian 1.0\nelement vertex 999999999\n"
            "property float x\nproperty float y\nproperty float z\nend_header\n");
  dir.write("poses.csv", "file,x,y,z,yaw_deg\nbad.ply,0,0,0,0\ngood.ply,1,0,0,0\n");
  const ReplayFolder folder(dir.path());
  ASSERT_EQ(folder.size(), 2u);
  expect_error([&] { folder.load(0); }, {"bad.ply"});
  EXPECT_EQ(folder.load(1).size(), 2u);  // playback goes on with the next scan
}

TEST(ReplayFolder, FolderErrors) {
  TempDir dir;
  expect_folder_error(dir.path() / "nope", {"nope", "no such directory"});
  dir.write("file.txt", "x");
  expect_folder_error(dir.path() / "file.txt", {"not a directory"});
  expect_folder_error(dir.path(), {"neither poses.csv nor 3DTK scanNNN.3d"});
}

TEST(ReplayFolder, ListsThreedtkScansByNumber) {
  TempDir dir;
  dir.write("scan10.3d", "100 0 0\n");
  dir.write("scan10.pose", "0 0 0\n0 0 0\n");
  dir.write("scan2.3d", "0 0 100\n0 0 0\n");
  // 3DTK: forward 1 m (its z), turned +90 degrees about its up axis (y).
  dir.write("scan2.pose", "0 0 100\n0 90 0\n");
  dir.write("scan2.jpg", "jpeg");
  dir.write("scanner.3d", "not a scan: the name has no number");
  const ReplayFolder folder(dir.path());
  ASSERT_EQ(folder.size(), 2u);
  EXPECT_EQ(folder.entry(0).scan, dir.path() / "scan2.3d");
  EXPECT_EQ(folder.entry(1).scan, dir.path() / "scan10.3d");
  const Pose& p = folder.entry(0).pose;
  EXPECT_NEAR(p.x, 1, 1e-12);
  EXPECT_NEAR(p.y, 0, 1e-12);
  EXPECT_NEAR(p.z, 0, 1e-12);
  EXPECT_NEAR(p.yaw, -M_PI / 2, 1e-12);  // handedness flips the sense of turning
  ASSERT_TRUE(folder.entry(0).image.has_value());
  EXPECT_FALSE(folder.entry(1).image.has_value());
  const PointCloud c = folder.load(0);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_TRUE(c.points[0].isApprox(Eigen::Vector3f(1, 0, 0)));
}

TEST(ReplayFolder, ThreedtkErrors) {
  {
    TempDir dir;
    dir.write("scan000.3d", "1 2 3\n");
    expect_folder_error(dir.path(), {"scan000.pose", "missing"});
  }
  {
    TempDir dir;
    dir.write("scan000.3d", "1 2 3\n");
    dir.write("scan000.pose", "1 2 3\n4 5\n");
    expect_folder_error(dir.path(), {"scan000.pose", "expected 6 numbers"});
  }
  {
    TempDir dir;
    for (const char* stem : {"scan1", "scan001"}) {
      dir.write(std::string(stem) + ".3d", "1 2 3\n");
      dir.write(std::string(stem) + ".pose", "0 0 0 0 0 0\n");
    }
    expect_folder_error(dir.path(), {"the same scan number"});
  }
}

TEST(ReplayFolder, PlaysTheThreedtkSampleFolder) {
  const fs::path data = test_support::threedtk_sample_dir();
  if (!fs::exists(data / "scan000.3d")) {
    GTEST_SKIP() << "3DTK sample scans not found at " << data;
  }
  const ReplayFolder folder(data);
  ASSERT_EQ(folder.size(), 3u);
  EXPECT_EQ(folder.entry(2).scan.filename(), "scan002.3d");
  // scan001.pose: (-3.10605, -7.50803, 156.917) cm -> x = 156.917 / 100 m in our frame.
  EXPECT_NEAR(folder.entry(1).pose.x, 1.56917, 1e-9);
  EXPECT_EQ(folder.load(1).size(), 81360u);
}

}  // namespace
}  // namespace scanplan

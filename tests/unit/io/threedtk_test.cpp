#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <random>
#include <sstream>
#include <string>

#include "scan_file_test_support.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/io/threedtk.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;
using test_support::expect_error;

const fs::path kData = test_support::threedtk_sample_dir();

#define SKIP_WITHOUT_DATA()                                                          \
  if (!fs::exists(kData / "scan000.3d")) {                                           \
    GTEST_SKIP() << "3DTK sample scans not found at " << kData                       \
                 << " (they live in shared/, beside the repository, not inside it)"; \
  }

// 3DTK's own Euler-to-matrix formula (EulerToMatrix4), written out element by element, so the
// test does not just repeat the reader's composition of rotations.
Eigen::Matrix3d threedtk_euler(double rx, double ry, double rz) {
  const double sx = std::sin(rx), cx = std::cos(rx), sy = std::sin(ry), cy = std::cos(ry),
               sz = std::sin(rz), cz = std::cos(rz);
  Eigen::Matrix3d M;
  M << cy * cz, -cy * sz, sy,                                     //
      sx * sy * cz + cx * sz, -sx * sy * sz + cx * cz, -sx * cy,  //
      -cx * sy * cz + sx * sz, cx * sy * sz + sx * cz, cx * cy;
  return M;
}

TEST(Threedtk, BasisTurnsYUpLeftHandedIntoZUpRightHanded) {
  const Eigen::Matrix3d C = threedtk_to_ours_basis();
  EXPECT_TRUE((C * Eigen::Vector3d(1, 2, 3)).isApprox(Eigen::Vector3d(3, -1, 2)));
  EXPECT_DOUBLE_EQ(C.determinant(), -1.0);  // a change of handedness
  EXPECT_TRUE((C * C.transpose()).isIdentity());
  // 3DTK's up axis (y) becomes ours (z); its forward axis (z) becomes ours (x).
  EXPECT_TRUE((C * Eigen::Vector3d::UnitY()).isApprox(Eigen::Vector3d::UnitZ()));
  EXPECT_TRUE((C * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX()));
}

TEST(Threedtk, ScanPointsAreConvertedAndShortReturnsDropped) {
  ThreedtkScanInfo info;
  const PointCloud c =
      parse_threedtk_scan("100 200 300\n\n0 0 0\r\n1 1 1\n-50 +0 1e2\nnan 1 1\n", "s.3d", &info);
  ASSERT_EQ(c.size(), 2u);
  EXPECT_TRUE(c.points[0].isApprox(Eigen::Vector3f(3, -1, 2)));
  EXPECT_TRUE(c.points[1].isApprox(Eigen::Vector3f(1, 0.5f, 0)));
  EXPECT_FALSE(c.has_colors());
  EXPECT_EQ(info.lines, 5u);
  EXPECT_EQ(info.dropped_short, 2u);  // (0,0,0) and (1,1,1) cm are within 5 cm
  EXPECT_EQ(info.dropped_non_finite, 1u);

  ThreedtkScanOptions range;
  range.min_range_m = 1.5;
  range.max_range_m = 3.0;
  EXPECT_EQ(parse_threedtk_scan("100 0 0\n200 0 0\n400 0 0\n", "s.3d", &info, range).size(), 1u);
  EXPECT_EQ(info.dropped_short, 1u);
  EXPECT_EQ(info.dropped_far, 1u);
}

TEST(Threedtk, ScanErrorsNameFileAndLine) {
  expect_error([] { parse_threedtk_scan("1 2 3\n1 2\n", "s.3d"); },
               {"s.3d", "line 2", "expected 3 numbers", "got 2"});
  expect_error([] { parse_threedtk_scan("1 2 3 4\n", "s.3d"); }, {"line 1", "got 4"});
  expect_error([] { parse_threedtk_scan("1 2 3\n\n1 2 x\n", "s.3d"); },
               {"line 3", "'x' is not a number"});
  expect_error([] { read_threedtk_scan("/nonexistent/scan000.3d"); },
               {"scan000.3d", "no such file"});
}

TEST(Threedtk, PoseUsesThreedtkEulerOrderAndOurFrame) {
  const double rx = 10, ry = 20, rz = 30;  // degrees
  const Eigen::Isometry3d T =
      parse_threedtk_pose("100 -200 300\n" + std::to_string(rx) + " " + std::to_string(ry) + " " +
                              std::to_string(rz) + "\n",
                          "p.pose");
  const Eigen::Matrix3d C = threedtk_to_ours_basis();
  const Eigen::Matrix3d R = threedtk_euler(deg2rad(rx), deg2rad(ry), deg2rad(rz));
  EXPECT_TRUE(T.linear().isApprox(C * R * C.transpose(), 1e-12));
  // (100, -200, 300) cm -> (z, -x, y)/100 = (3, -1, -2) m.
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(3, -1, -2)));

  // Turning about 3DTK's up axis by +90 degrees is a turn of -90 degrees about ours: the
  // handedness flips the sense of rotation.
  const Pose p = Pose::from_isometry(parse_threedtk_pose("0 0 0 0 90 0", "yaw.pose"));
  EXPECT_NEAR(p.yaw, -M_PI / 2, 1e-12);
  EXPECT_NEAR(p.roll, 0, 1e-12);
  EXPECT_NEAR(p.pitch, 0, 1e-12);
}

TEST(Threedtk, PoseAndPointsConvertConsistently) {
  // Moving a point by a 3DTK pose and then converting must equal converting both first.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> deg(-180, 180), cm(-500, 500);
  const Eigen::Matrix3d C = threedtk_to_ours_basis();
  for (int trial = 0; trial < 20; ++trial) {
    const Eigen::Vector3d t(cm(rng), cm(rng), cm(rng)), angles(deg(rng), deg(rng), deg(rng));
    const Eigen::Vector3d p(cm(rng), cm(rng), cm(rng));
    const Eigen::Matrix3d R =
        threedtk_euler(deg2rad(angles.x()), deg2rad(angles.y()), deg2rad(angles.z()));
    const Eigen::Vector3d world_3dtk = R * p + t;

    std::ostringstream pose;
    pose.precision(17);
    pose << t.x() << ' ' << t.y() << ' ' << t.z() << '\n'
         << angles.x() << ' ' << angles.y() << ' ' << angles.z() << '\n';
    const Eigen::Isometry3d T = parse_threedtk_pose(pose.str(), "r.pose");
    EXPECT_TRUE((T * (C * p / 100)).isApprox(C * world_3dtk / 100, 1e-9)) << "trial " << trial;

    // The same pose as a column-major .reference matrix gives the same transform.
    std::ostringstream ref;
    ref.precision(17);
    for (int col = 0; col < 4; ++col) {
      for (int row = 0; row < 4; ++row) {
        const double v = row < 3 ? (col < 3 ? R(row, col) : t[row]) : (col < 3 ? 0.0 : 1.0);
        ref << v << ' ';
      }
    }
    ref << "2\n";
    EXPECT_TRUE(parse_threedtk_reference(ref.str(), "r.reference").isApprox(T, 1e-9));
  }
}

TEST(Threedtk, PoseAndReferenceErrors) {
  expect_error([] { parse_threedtk_pose("1 2 3\n4 5\n", "p.pose"); },
               {"p.pose", "expected 6 numbers", "got 5"});
  expect_error([] { parse_threedtk_pose("1 2 3\n4 five 6\n", "p.pose"); },
               {"line 2", "'five' is not a finite number"});
  expect_error([] { parse_threedtk_pose("1 2 3\n4 5 6\n7\n", "p.pose"); },
               {"line 3", "after 6 numbers"});
  expect_error([] { parse_threedtk_pose("1 2 3\n4 nan 6\n", "p.pose"); }, {"'nan'"});
  expect_error([] { parse_threedtk_reference("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0", "r.ref"); },
               {"r.ref", "expected 16 numbers", "got 15"});
  expect_error([] { parse_threedtk_reference("2 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "r.ref"); },
               {"not a rotation"});
  expect_error([] { parse_threedtk_reference("1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 5", "r.ref"); },
               {"last row"});
  // A mirror is orthonormal but no rotation.
  expect_error([] { parse_threedtk_reference("-1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1", "r.ref"); },
               {"not a rotation"});
}

TEST(Threedtk, ReadsTheSampleScans) {
  SKIP_WITHOUT_DATA();
  // Counted independently with awk over the raw files: every file has 81,360 lines, none
  // within 5 cm of the origin (the nearest return is 9.5 cm away), so the default keeps all.
  for (const char* name : {"scan000.3d", "scan001.3d", "scan002.3d"}) {
    ThreedtkScanInfo info;
    const PointCloud c = read_threedtk_scan(kData / name, &info);
    EXPECT_EQ(info.lines, 81360u) << name;
    EXPECT_EQ(c.size(), 81360u) << name;
    EXPECT_EQ(info.dropped_short + info.dropped_non_finite + info.dropped_far, 0u) << name;
  }
  // The near-field clutter of the mount (under 20 cm) and the saturated returns at 32.76 m
  // (a range of 0x7fff mm), with awk: sqrt(x*x+y*y+z*z) < 20 resp. > 3270.
  const std::array<std::array<std::size_t, 3>, 3> expected{{
      {1892, 1481, 77987},
      {1727, 1313, 78320},
      {1624, 1618, 78118},
  }};
  ThreedtkScanOptions range;
  range.min_range_m = 0.20;
  range.max_range_m = 32.70;
  for (int i = 0; i < 3; ++i) {
    const std::string name = "scan00" + std::to_string(i) + ".3d";
    ThreedtkScanInfo info;
    const PointCloud c = read_threedtk_scan(kData / name, &info, range);
    EXPECT_EQ(info.dropped_short, expected[i][0]) << name;
    EXPECT_EQ(info.dropped_far, expected[i][1]) << name;
    EXPECT_EQ(c.size(), expected[i][2]) << name;
  }
}

TEST(Threedtk, ConvertedSampleScanIsZUp) {
  SKIP_WITHOUT_DATA();
  // scan000 stands on a floor about 0.38 m below the scanner (in the raw file, 3DTK's y of
  // nearby points piles up at -35..-40 cm). After conversion that floor must be the most
  // common height, and below the scanner, which is only so if z is up.
  const PointCloud c = read_threedtk_scan(kData / "scan000.3d");
  std::map<int, int> bins;  // 5 cm slabs of z, for points 0.3-3 m away horizontally
  for (const auto& p : c.points) {
    const float h = p.head<2>().norm();
    if (h > 0.3f && h < 3.0f) ++bins[static_cast<int>(std::floor(p.z() / 0.05f))];
  }
  const auto mode = std::max_element(
      bins.begin(), bins.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  ASSERT_NE(mode, bins.end());
  EXPECT_GE(mode->first * 0.05, -0.45);
  EXPECT_LE(mode->first * 0.05, -0.30);
}

TEST(Threedtk, ReadsTheSamplePosesAndReferences) {
  SKIP_WITHOUT_DATA();
  const Eigen::Isometry3d p0 = read_threedtk_pose(kData / "scan000.pose");
  EXPECT_TRUE(p0.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  EXPECT_TRUE(read_threedtk_reference(kData / "scan000.reference")
                  .isApprox(Eigen::Isometry3d::Identity(), 1e-12));

  // scan001.reference holds the translation (-3.6331, -9.08315, 156.796) cm as its numbers
  // 13-15; (x, y, z) -> (z, -x, y)/100 gives (1.56796, 0.036331, -0.0908315) m.
  const Eigen::Isometry3d r1 = read_threedtk_reference(kData / "scan001.reference");
  EXPECT_NEAR(r1.translation().x(), 1.56796, 1e-9);
  EXPECT_NEAR(r1.translation().y(), 0.036331, 1e-9);
  EXPECT_NEAR(r1.translation().z(), -0.0908315, 1e-9);
  // Its rotation: the file's third column is (-0.0124799, -0.0130579, 0.999837); in our frame
  // C·R·Cᵀ has (0, 0) = R(2, 2) = 0.999837 and (1, 0) = -R(0, 2) = 0.0124799.
  EXPECT_NEAR(r1.linear()(0, 0), 0.999837, 1e-9);
  EXPECT_NEAR(r1.linear()(1, 0), 0.0124799, 1e-9);

  // Odometry and registration agree to about 2 cm and under 1 degree (README), which holds
  // only if both files are decoded with the same conventions.
  for (const char* stem : {"scan001", "scan002"}) {
    const Eigen::Isometry3d odo = read_threedtk_pose(kData / (std::string(stem) + ".pose"));
    const Eigen::Isometry3d ref =
        read_threedtk_reference(kData / (std::string(stem) + ".reference"));
    EXPECT_LT((odo.translation() - ref.translation()).norm(), 0.025) << stem;
    const double angle = Eigen::AngleAxisd(odo.linear().transpose() * ref.linear()).angle();
    EXPECT_LT(rad2deg(angle), 1.0) << stem;
  }
  // scan001's odometry: (-3.10605, -7.50803, 156.917) cm -> (1.56917, 0.0310605, -0.0750803) m.
  const Eigen::Isometry3d p1 = read_threedtk_pose(kData / "scan001.pose");
  EXPECT_TRUE(p1.translation().isApprox(Eigen::Vector3d(1.56917, 0.0310605, -0.0750803), 1e-9));
}

}  // namespace
}  // namespace scanplan

// Line-segment ICP (paper §4.1) on its own: from a near start it lands on the truth, it measures
// to the segment between target points rather than to the nearest point, and without overlap it
// says so.
#include <gtest/gtest.h>

#include "registration_test_support.hpp"
#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/registration/line_segment_icp.hpp"

namespace scanplan {
namespace {

using test::error_of;
using test::moved;
using test::pose;
using test::synthetic_yard;

TEST(LineSegmentIcp, FromANearStartLandsOnTheTruth) {
  // Thinned as register_scans thins them (RegistrationConfig: 0.4 m voxels, the source to 0.8 m).
  const PointCloud target = voxel_downsample(synthetic_yard(1), 0.4);
  const Eigen::Isometry3d truth = pose(2.0, -1.0, 0.05, 12).isometry();
  const PointCloud source = moved(voxel_downsample(synthetic_yard(2), 0.4), truth.inverse());
  const Eigen::Isometry3d start = pose(2.3, -1.2, 0.05, 14).isometry();
  IcpConfig c;
  c.source_voxel_m = 0.8;
  for (Dof dof : {Dof::k4, Dof::k6}) {
    const RegistrationResult r = align_line_segment_icp(target, source, start, dof, c);
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_LT(error_of(r.transform, truth).metres, 0.02);
    EXPECT_LT(error_of(r.transform, truth).degrees, 0.1);
    EXPECT_GT(r.iterations, 1);
  }
}

TEST(LineSegmentIcp, MeasuresToTheSegmentBetweenSparseTargetPoints) {
  // The target: rows of points 0.5 m apart on two perpendicular walls and a floor. The source
  // samples the same surfaces densely, shifted 5 cm. Point-to-point pairs would pull the source
  // points towards the sparse target points (a bias of up to a quarter of the spacing); the
  // distance to the segment between the two closest points has no such pull along a row.
  PointCloud target, surfaces;
  for (double a = -10; a <= 10; a += 0.5) {
    for (double b = 0; b <= 3; b += 0.5) {
      target.points.emplace_back(a, 10, b);     // wall facing -y
      target.points.emplace_back(10, a, b);     // wall facing -x
      target.points.emplace_back(a, b * 3, 0);  // floor
    }
  }
  for (double a = -9.8; a <= 9.8; a += 0.07) {
    for (double b = 0.03; b <= 2.9; b += 0.23) {
      surfaces.points.emplace_back(a, 10, b);
      surfaces.points.emplace_back(10, a, b);
      surfaces.points.emplace_back(a, b * 3, 0);
    }
  }
  const Eigen::Isometry3d truth = pose(0.05, -0.04, 0, 0.3).isometry();
  const PointCloud source = moved(surfaces, truth.inverse());
  IcpConfig c;
  c.min_correspondence_m = 0.3;
  const RegistrationResult r =
      align_line_segment_icp(target, source, Eigen::Isometry3d::Identity(), Dof::k4, c);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_LT(error_of(r.transform, truth).metres, 0.01);
}

TEST(LineSegmentIcp, WithoutOverlapItSaysSo) {
  const PointCloud target = voxel_downsample(synthetic_yard(1), 0.4);
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(500, 0, 0);
  const RegistrationResult r = align_line_segment_icp(
      target, moved(target, far), Eigen::Isometry3d::Identity(), Dof::k4, IcpConfig{});
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.message.empty());
}

}  // namespace
}  // namespace scanplan

// The coarse stage of scan-to-map matching: a search over the whole pose uncertainty finds the
// true pose among its peaks from starts that a local method cannot reach from, best first.
#include <gtest/gtest.h>

#include <cmath>

#include "registration_test_support.hpp"
#include "scanplan/registration/pose_search.hpp"
#include "scanplan/registration/registration.hpp"

namespace scanplan {
namespace {

using test::error_of;
using test::Errors;
using test::moved;
using test::pose;
using test::synthetic_yard;

class PoseSearch : public ::testing::Test {
 protected:
  void SetUp() override {
    target_ = synthetic_yard(1);
    truth_ = pose(2.0, -1.0, 0.0, 10).isometry();
    source_ = moved(synthetic_yard(2), truth_.inverse());
  }
  PointCloud target_, source_;
  Eigen::Isometry3d truth_;
};

TEST_F(PoseSearch, FindsTheTruePoseAmongItsPeaksFromFarOff) {
  // 4.5 m and 22° off: three sigma of the pose sensors the benchmark assumes (2 m, 10°).
  const Eigen::Isometry3d initial = pose(5.5, -4.0, 0.2, 32).isometry();
  const std::vector<PoseHypothesis> peaks = search_poses(target_, source_, initial);
  ASSERT_FALSE(peaks.empty());
  EXPECT_LE(peaks.size(), 3u);
  for (std::size_t i = 1; i < peaks.size(); ++i) {
    EXPECT_GE(peaks[i - 1].score, peaks[i].score) << "best first";
  }
  const Errors best = error_of(peaks.front().transform, truth_);
  // Within the fine grid's step and turn: what the refinement's basin takes from there.
  EXPECT_LT(best.metres, 0.6);
  EXPECT_LT(best.degrees, 2.0);
  EXPECT_GT(peaks.front().score, 0.3);
}

TEST_F(PoseSearch, KeepsRollAndPitchOfTheStart) {
  const Eigen::Isometry3d initial = pose(3.0, 0.0, 0.0, 14, 1.5, -1.0).isometry();
  for (const PoseHypothesis& h : search_poses(target_, source_, initial)) {
    const Pose got = Pose::from_isometry(h.transform);
    EXPECT_NEAR(rad2deg(got.roll), 1.5, 1e-6);
    EXPECT_NEAR(rad2deg(got.pitch), -1.0, 1e-6);
  }
}

TEST_F(PoseSearch, NothingToSearchGivesNoPeaks) {
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  EXPECT_TRUE(search_poses(PointCloud{}, source_, I).empty());
  EXPECT_TRUE(search_poses(target_, PointCloud{}, I).empty());
  PoseSearchConfig bad;
  bad.cell_m = 0;
  EXPECT_TRUE(search_poses(target_, source_, I, bad).empty());
}

TEST_F(PoseSearch, SearchThenGicpRecoversWhatGicpAloneCannotReach) {
  RegistrationConfig c;
  c.voxel_m = 0.4;
  const Eigen::Isometry3d initial = pose(6.0, -5.0, 0.2, 35).isometry();  // 6 m, 25° off
  const RegistrationResult searched =
      register_scans(target_, source_, initial, Method::kSearchGicp, c);
  const Errors e = error_of(searched.transform, truth_);
  EXPECT_TRUE(searched.converged) << searched.message;
  EXPECT_LT(e.metres, 0.01);
  EXPECT_LT(e.degrees, 0.05);
}

// A row of equal posts every 6 m, of which the map holds those east of the scan's true
// position only: shifted one post east, more of the scan lands on the map than where it truly
// is, so the look-alike scores best. The odometry's prior (σ 1.5 m around the truth) puts it
// back in second place.
TEST(PoseSearchPrior, ALookAlikeFartherFromThePriorDoesNotComeFirst) {
  const auto posts = [](int first, int last) {
    PointCloud c;
    for (int i = first; i <= last; ++i) {
      for (float z = 0; z <= 2.0f; z += 0.1f) {
        for (float dx = -0.2f; dx <= 0.2f; dx += 0.1f) {
          for (float dy = -0.2f; dy <= 0.2f; dy += 0.1f) {
            c.points.emplace_back(6.0f * static_cast<float>(i) + dx, 5.0f + dy, z);
          }
        }
      }
    }
    return c;
  };
  const PointCloud map = posts(0, 20);   // x 0..120
  const PointCloud scan = posts(-5, 5);  // the scan at x = 0 sees x -30..30
  PoseSearchConfig c;
  c.xy_range_m = 7;
  c.yaw_range_deg = 3;
  const Eigen::Isometry3d I = Eigen::Isometry3d::Identity();
  const std::vector<PoseHypothesis> flat = search_poses(map, scan, I, c);
  ASSERT_FALSE(flat.empty());
  EXPECT_NEAR(flat.front().transform.translation().x(), 6.0, 0.6) << "the look-alike first";
  c.prior_sigma_xy_m = 1.5;
  c.prior_sigma_yaw_deg = 3;
  const std::vector<PoseHypothesis> known = search_poses(map, scan, I, c);
  ASSERT_FALSE(known.empty());
  EXPECT_LT(known.front().transform.translation().head<2>().norm(), 0.6);
  // The weight itself: 1 at the prior, exp(-½ (d/σ)²) off it, nothing without a σ.
  EXPECT_EQ(prior_weight(c, I, I), 1.0);
  Eigen::Isometry3d off = I;
  off.translate(Eigen::Vector3d(3.0, 0, 0));
  EXPECT_NEAR(prior_weight(c, I, off), std::exp(-2.0), 1e-12);
  EXPECT_EQ(prior_weight(PoseSearchConfig{}, I, off), 1.0);
}

}  // namespace
}  // namespace scanplan

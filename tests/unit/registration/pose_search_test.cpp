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

}  // namespace
}  // namespace scanplan

// Narrower NDT (paper §4.2) on its own: the cell schedule pulls a start metres off onto the
// truth, the 4-DOF solver keeps roll and pitch, and clouds that do not overlap are refused.
#include <gtest/gtest.h>

#include "registration_test_support.hpp"
#include "scanplan/geometry/voxel_filter.hpp"
#include "scanplan/registration/narrower_ndt.hpp"

namespace scanplan {
namespace {

using test::error_of;
using test::moved;
using test::pose;
using test::synthetic_yard;

// The paper's 20/15/10 m suit scenes of 50 m; the 30 m synthetic yard gets a fifth of them, as
// RegistrationConfig::adapt_to_scene would give it.
NdtConfig yard_config() {
  NdtConfig c;
  c.cell_sizes_m = {4.0, 3.0, 2.0};
  return c;
}

class NarrowerNdt : public ::testing::Test {
 protected:
  void SetUp() override {
    target_ = voxel_downsample(synthetic_yard(1), 0.4);
    world_ = voxel_downsample(synthetic_yard(2), 0.4);
  }
  PointCloud target_, world_;
};

TEST_F(NarrowerNdt, PullsAStartMetresOffOntoTheTruth) {
  const Eigen::Isometry3d truth = pose(2.0, -1.0, 0.05, 12).isometry();
  const PointCloud source = moved(world_, truth.inverse());
  const Eigen::Isometry3d start = pose(3.2, 0.1, 0.2, 20).isometry();
  ASSERT_GT(error_of(start, truth).metres, 1.5);
  const RegistrationResult r = align_narrower_ndt(target_, source, start, Dof::k4, yard_config());
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_LT(error_of(r.transform, truth).metres, 0.05);
  EXPECT_LT(error_of(r.transform, truth).degrees, 0.2);
  EXPECT_GT(r.iterations, 3) << "at least one Newton step per cell size";
}

TEST_F(NarrowerNdt, FourDofKeepsTheMeasuredRollAndPitch) {
  const Pose truth = pose(1.0, 0.5, 0.0, 8, 1.5, -1.0);
  const PointCloud source = moved(world_, truth.isometry().inverse());
  const Pose start = pose(1.6, 0.0, 0.1, 4, 1.5, -1.0);
  const RegistrationResult r =
      align_narrower_ndt(target_, source, start.isometry(), Dof::k4, yard_config());
  const Pose got = Pose::from_isometry(r.transform);
  EXPECT_NEAR(got.roll, start.roll, 1e-9);
  EXPECT_NEAR(got.pitch, start.pitch, 1e-9);
  EXPECT_LT(error_of(r.transform, truth.isometry()).metres, 0.05);
}

TEST_F(NarrowerNdt, CloudsThatDoNotOverlapAreRefused) {
  Eigen::Isometry3d far = Eigen::Isometry3d::Identity();
  far.translation() = Eigen::Vector3d(500, 0, 0);
  NdtConfig c = yard_config();
  c.yaw_hypotheses_deg = {0};
  c.translation_search_steps = 0;
  const RegistrationResult r =
      align_narrower_ndt(target_, moved(world_, far), Eigen::Isometry3d::Identity(), Dof::k4, c);
  EXPECT_FALSE(r.converged);
  EXPECT_FALSE(r.message.empty());
}

}  // namespace
}  // namespace scanplan

// Scan matching on real data (issue 6): the three 3DTK sample scans (a SICK scanner on a rotating
// mount, as in the paper), matched pairwise from starts perturbed by 0.5 m and 5° and compared
// with the poses slam6D computed for them (`.reference`). The issue asks for 2 cm and 0.5°.
//
// ThreedtkReference: what the reference is. slam6D with its defaults (pairwise closest-point ICP
// on every point, 25 cm, 50 iterations; slam6d_icp_test_support.hpp) reproduces scan001's pose
// from the odometry to 0.1 mm and 0.002°, which also pins down the conversion of 3DTK's frame
// (left-handed, y up, cm, R = Rx·Ry·Rz, column-major). scan002's pose is not where that ICP
// ends: run on these files it ends 3.1 cm and 1.0° away (3.4 cm, 1.03° when run to convergence),
// and the file sits within 1.3 mm and 0.06° of its FIRST iteration from the odometry. So
// against scan002.reference "agrees with slam6D" means "stays at the odometry", and no matcher
// that converges can be held to 2 cm and 0.5° there.
//
// ThreedtkRegistration: what we reach, worst of six seeded starts per case (all starts land
// within 1 mm of one another):
//   001→000  6 DOF, roll/pitch from odometry       1.2 cm 0.42°   (meets 2 cm / 0.5°)
//   002→001  6 DOF, roll/pitch from odometry       3.0 cm 0.31°   (reference not converged)
//   001→000  4 DOF, roll/pitch from .reference     3.7 cm 0.07°
//   002→001  4 DOF, roll/pitch from .reference     3.0 cm 0.13°   (reference not converged)
// The 1.7 cm left in 001→000 at 4 DOF is the difference between two estimators, not an error of
// either that this data could show: in this corridor-like, floor-dominated scene, whose floor
// the scanner sees tilted by 4° within 1.5 m and by 0.3° within 6 m, reasonable matchers
// disagree by 1–8 cm and up to 3.4° (docs/benchmarks.md, "Real data"), and slam6D's own answer
// moves by 4 cm when its input is thinned to 2 cm voxels. Our answer on this data also rides on
// the sampling: thinning voxels 0.5 % (0.8 mm) larger move 001→000 at 6 DOF from 1.2 cm, 0.42°
// to 4.4 cm, 0.96°, so the one case within the target has less margin than its
// numbers suggest; a change of the thinning that fails it is not by itself a regression.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "io/scan_file_test_support.hpp"
#include "scanplan/geometry/pose.hpp"
#include "scanplan/io/threedtk.hpp"
#include "scanplan/registration/registration.hpp"
#include "slam6d_icp_test_support.hpp"

namespace scanplan {
namespace {

namespace fs = std::filesystem;

struct Errors {
  double cm, deg;
};

Errors error_of(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d e = truth.inverse() * estimate;
  return {100 * e.translation().norm(), rad2deg(Eigen::AngleAxisd(e.linear()).angle())};
}

// The sample scans, read once for every test here.
class ThreedtkData {
 public:
  // Null when the data is not there.
  static const ThreedtkData* get() {
    static const std::unique_ptr<const ThreedtkData> data = load();
    return data.get();
  }
  // Scan k relative to scan k−1 (k = 1, 2) as slam6D's .reference poses and the odometry give.
  Eigen::Isometry3d reference(int k) const { return reference_[k - 1].inverse() * reference_[k]; }
  Eigen::Isometry3d odometry(int k) const { return odometry_[k - 1].inverse() * odometry_[k]; }

  // For our matcher: the README of the data says the scanner's own mount shows up within 20 cm
  // and saturated beams at 32.76 m. The mount moves with the scanner, so left in it would pull
  // every match towards "no motion at all" (it does: 1.6 m off).
  std::vector<PointCloud> scans;
  // For slam6D as it ran: every point but the missed beams at the origin.
  std::vector<PointCloud> raw;

 private:
  static std::unique_ptr<const ThreedtkData> load() {
    const fs::path dir = test_support::threedtk_sample_dir();
    if (!fs::exists(dir / "scan000.3d")) return nullptr;
    auto d = std::make_unique<ThreedtkData>();
    ThreedtkScanOptions cut;
    cut.min_range_m = 0.3;
    cut.max_range_m = 32.0;
    for (int i = 0; i < 3; ++i) {
      const fs::path stem = dir / ("scan00" + std::to_string(i));
      d->scans.push_back(read_threedtk_scan(stem.string() + ".3d", nullptr, cut));
      d->raw.push_back(read_threedtk_scan(stem.string() + ".3d"));
      d->reference_.push_back(read_threedtk_reference(stem.string() + ".reference"));
      d->odometry_.push_back(read_threedtk_pose(stem.string() + ".pose"));
    }
    return d;
  }
  std::vector<Eigen::Isometry3d> reference_, odometry_;
};

#define SKIP_WITHOUT_3DTK_DATA()                                                             \
  if (!ThreedtkData::get()) {                                                                \
    GTEST_SKIP() << "3DTK sample scans not found at " << test_support::threedtk_sample_dir() \
                 << " (they live in shared/, beside the repository, not inside it)";         \
  }

// ---------------------------------------------------------------------------------------------
// How the reference poses were made.

constexpr int kSlam6dIterations = 50;  // slam6D's default `-i`

TEST(ThreedtkReference, Scan001IsSlam6dPairwiseIcpFromTheOdometry) {
  SKIP_WITHOUT_3DTK_DATA();
  const ThreedtkData& d = *ThreedtkData::get();
  const test_support::Slam6dIcpResult r =
      test_support::slam6d_icp(d.raw[0], d.raw[1], d.odometry(1), kSlam6dIterations);
  const Errors e = error_of(r.transform, d.reference(1));
  // 0.09 mm and 0.0015° measured: what is left is float storage of the points and the end of
  // the iterations, not a difference of method or of frame convention (either costs centimetres).
  EXPECT_LT(e.cm, 0.02);
  EXPECT_LT(e.deg, 0.005);
  RecordProperty("scan001_slam6d_vs_reference_cm", std::to_string(e.cm));
}

TEST(ThreedtkReference, Scan002IsNotWhereSlam6dConverges) {
  SKIP_WITHOUT_3DTK_DATA();
  const ThreedtkData& d = *ThreedtkData::get();
  const Eigen::Isometry3d start = d.odometry(2);
  const Errors full =
      error_of(test_support::slam6d_icp(d.raw[1], d.raw[2], start, kSlam6dIterations).transform,
               d.reference(2));
  // slam6D on these files, as configured for scan001, ends 3.1 cm and 1.0° from the file: a
  // match that agrees with slam6D cannot be within 2 cm and 0.5° of scan002.reference.
  EXPECT_TRUE(full.cm > 2.0 || full.deg > 0.5) << full.cm << " cm, " << full.deg << "°";
  // The file is, to 1.3 mm and 0.06°, one iteration of that ICP from the odometry (not exactly:
  // the run that wrote it differed in some detail we cannot see, but not by much).
  const Errors first =
      error_of(test_support::slam6d_icp(d.raw[1], d.raw[2], start, 1).transform, d.reference(2));
  EXPECT_LT(first.cm, 0.3);
  EXPECT_LT(first.deg, 0.1);
  RecordProperty("scan002_slam6d_vs_reference_cm", std::to_string(full.cm));
  RecordProperty("scan002_slam6d_vs_reference_deg", std::to_string(full.deg));
}

// ---------------------------------------------------------------------------------------------
// Our matcher against the reference, after small_gicp's registration tests: named cases, each
// from several seeded starts, with explicit tolerances.

struct Case {
  const char* name;
  int scan;  // matched to scan − 1
  Dof dof;
  double max_cm, max_deg;
};

// The 2 cm / 0.5° where this data and its reference make it a test of the matcher
// (001→000, 6 DOF); elsewhere the bounds this test held before the reference was understood,
// not loosened (see the top of the file for why 2 cm / 0.5° does not apply there).
const Case kCases[] = {
    {"Scan001To000SixDof", 1, Dof::k6, 2.0, 0.5},
    {"Scan002To001SixDof", 2, Dof::k6, 3.5, 0.75},
    {"Scan001To000FourDofMeasuredTilt", 1, Dof::k4, 4.5, 0.25},
    {"Scan002To001FourDofMeasuredTilt", 2, Dof::k4, 4.5, 0.25},
};

class ThreedtkRegistration : public ::testing::TestWithParam<Case> {};

TEST_P(ThreedtkRegistration, AgreesWithSlam6dFromPerturbedStarts) {
  SKIP_WITHOUT_3DTK_DATA();
  const ThreedtkData& d = *ThreedtkData::get();
  const Case c = GetParam();
  const Eigen::Isometry3d truth = d.reference(c.scan);
  Pose start = Pose::from_isometry(d.odometry(c.scan));
  if (c.dof == Dof::k4) {
    // What an inclination sensor would add: roll and pitch as they are (here slam6D's), yaw and
    // position from the odometry.
    const Pose tilt = Pose::from_isometry(truth);
    start.roll = tilt.roll;
    start.pitch = tilt.pitch;
  }
  RegistrationConfig config;
  config.dof = c.dof;
  std::mt19937_64 rng(6 + c.scan);
  std::uniform_real_distribution<double> heading(-M_PI, M_PI);
  std::bernoulli_distribution left(0.5);
  double worst_cm = 0, worst_deg = 0;
  std::vector<Eigen::Isometry3d> results;
  for (int k = 0; k < 6; ++k) {
    // 0.5 m in a random horizontal direction and 5° of yaw either way: the perturbation.
    const double a = heading(rng);
    Eigen::Isometry3d initial = start.isometry();
    initial.translation() += 0.5 * Eigen::Vector3d(std::cos(a), std::sin(a), 0);
    initial.linear() =
        Eigen::AngleAxisd(deg2rad(left(rng) ? 5.0 : -5.0), Eigen::Vector3d::UnitZ()) *
        initial.linear();
    const RegistrationResult r =
        register_scans(d.scans[c.scan - 1], d.scans[c.scan], initial, Method::kNdtIcp, config);
    EXPECT_TRUE(r.converged) << "start " << k << ": " << r.message;
    const Errors e = error_of(r.transform, truth);
    EXPECT_LT(e.cm, c.max_cm) << "start " << k;
    EXPECT_LT(e.deg, c.max_deg) << "start " << k;
    worst_cm = std::max(worst_cm, e.cm);
    worst_deg = std::max(worst_deg, e.deg);
    results.push_back(r.transform);
  }
  // The answer is the matcher's, not the start's: every start ends at the same pose.
  double spread_cm = 0, spread_deg = 0;
  for (const Eigen::Isometry3d& T : results) {
    const Errors spread = error_of(T, results.front());
    EXPECT_LT(spread.cm, 0.5);
    EXPECT_LT(spread.deg, 0.05);
    spread_cm = std::max(spread_cm, spread.cm);
    spread_deg = std::max(spread_deg, spread.deg);
  }
  RecordProperty("worst_cm", std::to_string(worst_cm));
  RecordProperty("worst_deg", std::to_string(worst_deg));
  RecordProperty("spread_cm", std::to_string(spread_cm));
  RecordProperty("spread_deg", std::to_string(spread_deg));
}

INSTANTIATE_TEST_SUITE_P(Threedtk, ThreedtkRegistration, ::testing::ValuesIn(kCases),
                         [](const auto& param_info) { return std::string(param_info.param.name); });

TEST(ThreedtkRegistrationConfig, CellSizesShrinkForThisShortRangeScene) {
  SKIP_WITHOUT_3DTK_DATA();
  const PointCloud& scan = ThreedtkData::get()->scans[0];
  const RegistrationConfig c = adapted_config(scan, RegistrationConfig{});
  EXPECT_LT(scene_range_m(scan), 10.0);
  EXPECT_LT(c.ndt.cell_sizes_m.front(), 5.0) << "not the paper's 20 m";
  EXPECT_LT(c.voxel_m, 0.25);
}

}  // namespace
}  // namespace scanplan

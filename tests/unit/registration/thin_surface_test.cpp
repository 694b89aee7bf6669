// Thin surfaces seen from opposite sides (issue 17): a fence between two scanners shows each the
// face toward it, 10 cm apart. Without knowing where the scans were taken from, GICP pairs the
// faces and pulls the scans together by a share of the thickness; with the viewpoints it tells
// the faces apart (GicpConfig::min_normal_agreement) and stays at the truth.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "registration_test_support.hpp"
#include "scanplan/geometry/viewpoints.hpp"
#include "scanplan/registration/gicp.hpp"
#include "scanplan/registration/map_matcher.hpp"
#include "scanplan/registration/registration.hpp"

namespace scanplan {
namespace {

using test::error_of;

struct Face {
  Eigen::Vector3d corner, u, v;  // corner + a·u + b·v, a, b in [0, 1]
};

PointCloud sampled(const std::vector<Face>& faces, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, 0.005);
  PointCloud cloud;
  for (const Face& f : faces) {
    const int n = static_cast<int>(200 * f.u.cross(f.v).norm());  // 200 points a m²
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = f.corner + unit(rng) * f.u + unit(rng) * f.v;
      cloud.points.push_back(
          (p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).cast<float>());
    }
  }
  return cloud;
}

// The world: ground, a long building front to the north (fixes y and yaw), a short wall to the
// east (fixes x, weakly) and between the two scanners a fence 10 cm thick. The target scanner
// stands at x = −10, the source's at x = +10; each sees the fence's face toward it.
struct FenceScene {
  PointCloud target, source;  // source in its own frame, its origin at (10, 0, 0)
  Eigen::Isometry3d truth = Eigen::Isometry3d(Eigen::Translation3d(10, 0, 0));
  MatchViews views{Viewpoints::single({-10, 0, 1}), Viewpoints::single({0, 0, 1})};

  FenceScene() {
    const std::vector<Face> shared = {
        {{-15, -15, 0}, {30, 0, 0}, {0, 30, 0}},  // ground
        {{-15, 12, 0}, {30, 0, 0}, {0, 0, 6}},    // building front
        {{14, -3, 0}, {0, 6, 0}, {0, 0, 3}},      // east wall, west face
    };
    std::vector<Face> west = shared, east = shared;
    west.push_back({{0, -5, 0}, {0, 10, 0}, {0, 0, 1.2}});    // the fence's west face
    east.push_back({{0.1, -5, 0}, {0, 10, 0}, {0, 0, 1.2}});  // and its east face
    target = sampled(west, 1);
    source = test::moved(sampled(east, 2), truth.inverse());
  }
};

TEST(ThinSurfaces, GicpTellsAFencesFacesApartByWhereTheyWereSeenFrom) {
  const FenceScene scene;
  const GicpConfig config;
  const RegistrationResult blind =
      align_gicp(scene.target, scene.source, scene.truth, Dof::k4, config);
  const RegistrationResult seeing =
      align_gicp(scene.target, scene.source, scene.truth, Dof::k4, config, scene.views);
  ASSERT_TRUE(seeing.converged) << seeing.message;
  EXPECT_LT(error_of(seeing.transform, scene.truth).metres, 0.005);
  // The failure this guards against, as it shows here: started at the truth, pulled off.
  EXPECT_GT(error_of(blind.transform, scene.truth).metres, 0.02);

  // Viewpoints that do not describe the clouds are not used.
  const MatchViews wrong{Viewpoints{{{-10, 0, 1}}, {0, 0, 0}}, scene.views.source};
  const RegistrationResult ignored =
      align_gicp(scene.target, scene.source, scene.truth, Dof::k4, config, wrong);
  EXPECT_NEAR(error_of(ignored.transform, scene.truth).metres,
              error_of(blind.transform, scene.truth).metres, 1e-9);
}

TEST(ThinSurfaces, SearchGicpFromOffTheTruthWithViewpoints) {
  const FenceScene scene;
  const Eigen::Isometry3d start = Eigen::Translation3d(0.6, -0.4, 0) * scene.truth *
                                  Eigen::AngleAxisd(deg2rad(2), Eigen::Vector3d::UnitZ());
  const RegistrationResult r =
      register_scans(scene.target, scene.source, start, Method::kSearchGicp, {}, scene.views);
  ASSERT_TRUE(r.converged) << r.message;
  EXPECT_LT(error_of(r.transform, scene.truth).metres, 0.005);
  EXPECT_LT(error_of(r.transform, scene.truth).degrees, 0.02);
}

TEST(ThinSurfaces, TheMapMatchPassesTheMapsViewpointsOn) {
  // The map: the target scan as the map holds it, its points' scanner given per point (as
  // MissionPipeline::points_near gives them), the scan reported 40 cm and 1° off.
  const FenceScene scene;
  MatchViews views = scene.views;
  views.target.origin_of.assign(scene.target.size(), 0);
  const Pose truth = Pose::from_isometry(scene.truth);
  Pose reported = truth;
  reported.x += 0.3;
  reported.y -= 0.25;
  reported.yaw += deg2rad(1);
  const MapMatch seeing = match_to_map(scene.target, scene.source, reported, {}, views);
  const MapMatch blind = match_to_map(scene.target, scene.source, reported, {});
  ASSERT_TRUE(seeing.applied) << "[" << seeing.result.message << "]";
  EXPECT_LT(error_of(seeing.placed.isometry(), scene.truth).metres, 0.005);
  EXPECT_GT(error_of(blind.placed.isometry(), scene.truth).metres, 0.01);
}

}  // namespace
}  // namespace scanplan

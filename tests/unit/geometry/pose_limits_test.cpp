// A reported pose beyond any site is refused with a message naming the field (issue 16).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "scanplan/geometry/pose_limits.hpp"
#include "scanplan/geometry/target_region.hpp"

namespace scanplan {
namespace {

TEST(PoseLimits, ASitesPosesPass) {
  Pose p;
  EXPECT_FALSE(implausible_pose(p));
  p.x = -99999;
  p.y = 12345.6;
  p.z = -400;
  p.yaw = deg2rad(-359);
  p.roll = deg2rad(30);
  EXPECT_FALSE(implausible_pose(p));
}

TEST(PoseLimits, AbsurdButFiniteValuesAreRefusedByName) {
  struct Case {
    const char* field;
    Pose pose;
  };
  Pose far, huge, up, turned, nan;
  far.x = 1e7;
  huge.y = 1e308;
  up.z = -2e4;
  turned.yaw = deg2rad(10000);
  nan.pitch = std::numeric_limits<double>::quiet_NaN();
  for (const Case& c :
       {Case{"x", far}, Case{"y", huge}, Case{"z", up}, Case{"yaw", turned}, Case{"pitch", nan}}) {
    const auto why = implausible_pose(c.pose);
    ASSERT_TRUE(why) << c.field;
    EXPECT_NE(why->find(std::string("pose's ") + c.field + " is"), std::string::npos) << *why;
  }
}

TEST(TargetRegionLimits, ARegionBeyondAKilometreOrAThousandCornersIsRefused) {
  EXPECT_NO_THROW(TargetRegion::polygon({{0, 0}, {1000, 0}, {1000, 1000}, {0, 1000}}));
  try {
    TargetRegion::polygon({{0, 0}, {1e9, 0}, {1e9, 1e9}});
    FAIL() << "a region of 1e9 m would ask for more memory than there is";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("at most 1000 m a side"), std::string::npos) << e.what();
  }
  std::vector<Eigen::Vector2d> many;
  for (int i = 0; i < 1001; ++i) {
    const double a = 2 * M_PI * i / 1001;
    many.emplace_back(100 * std::cos(a), 100 * std::sin(a));
  }
  EXPECT_THROW(TargetRegion::polygon(many), std::invalid_argument);
}

}  // namespace
}  // namespace scanplan

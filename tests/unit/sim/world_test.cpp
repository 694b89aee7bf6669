#include <gtest/gtest.h>

#include "scanplan/sim/world.hpp"

namespace scanplan {
namespace {

std::string world_with(const std::string& objects, const std::string& extra = "") {
  return R"({"name": "t", "bounds": {"min": [-10, -10], "max": [10, 10]}, "ground": {"z": 0},
             "objects": [)" +
         objects + R"(], "start": [1, 2, 90])" + extra + "}";
}

void expect_error(const std::string& text, const std::string& fragment) {
  try {
    parse_world(text, "test.json");
    FAIL() << "expected a WorldError mentioning '" << fragment << "'";
  } catch (const WorldError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(World, ParsesBoxesStartAndOverrides) {
  const World w = parse_world(
      world_with(
          R"({"type": "box", "min": [0,0,0], "max": [1,2,3], "yaw_deg": 90, "color": [1,2,3]})",
          R"(, "scanner": {"max_range_m": 30}, "pose_noise": {"xy_sigma_m": 0})"),
      "t.json");
  ASSERT_EQ(w.boxes.size(), 1u);
  EXPECT_DOUBLE_EQ(w.boxes[0].max.z(), 3.0);
  EXPECT_NEAR(w.boxes[0].yaw, M_PI / 2, 1e-12);
  EXPECT_EQ(w.boxes[0].color, (Rgb{1, 2, 3}));
  EXPECT_DOUBLE_EQ(w.start.x, 1.0);
  EXPECT_NEAR(w.start.yaw, M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(w.scanner.max_range_m, 30.0);
  EXPECT_DOUBLE_EQ(w.scanner.vertical_step_deg, 0.5);
  EXPECT_DOUBLE_EQ(w.pose_noise.xy_sigma_m, 0.0);
  EXPECT_DOUBLE_EQ(w.pose_noise.yaw_sigma_deg, 5.0);
  EXPECT_EQ(w.pose_noise.model, OdometryModel::kDrift) << "drifting odometry unless told";
}

TEST(World, PoseNoiseChoosesItsModelAndFigures) {
  const World w =
      parse_world(world_with("", R"(, "pose_noise": {"model": "absolute", "xy_drift_fraction": 0.05,
                                          "yaw_drift_deg_per_10m": 1, "z_drift_fraction": 0})"),
                  "t.json");
  EXPECT_EQ(w.pose_noise.model, OdometryModel::kAbsolute);
  EXPECT_DOUBLE_EQ(w.pose_noise.xy_drift_fraction, 0.05);
  EXPECT_DOUBLE_EQ(w.pose_noise.yaw_drift_deg_per_10m, 1.0);
  expect_error(world_with("", R"(, "pose_noise": {"model": "gps"})"),
               "pose_noise: field 'model' must be \"drift\" or \"absolute\"");
  expect_error(world_with("", R"(, "pose_noise": {"xy_drift_fraction": -0.1})"),
               "must not be negative");
}

TEST(World, ErrorsNameTheObjectAndField) {
  expect_error(world_with(R"({"type": "pyramid"})"), "objects[0] (pyramid): field 'type'");
  expect_error(world_with(R"({"type": "box", "min": [0,0,0], "max": [1,-2,3]})"),
               "objects[0] (box): field 'max' must exceed");
  expect_error(world_with(R"({"type": "box", "min": [0,0], "max": [1,2,3]})"), "field 'min'");
  expect_error(world_with(R"({"type": "box", "min": [0,0,0], "max": [1,2,3], "colour": [1,1,1]})"),
               "field 'colour' is not a known field");
  expect_error(world_with(R"({"type": "box", "min": [0,0,0], "max": [1,2,3], "color": [1,1,300]})"),
               "within 0..255");
  expect_error(world_with("", R"(, "scanner": {"min_range_m": 90})"),
               "scanner: field 'min_range_m'");
  expect_error(world_with("", R"(, "extra": 1)"), "field 'extra' is not a known field");
  // JSON has no NaN literal: such a file is not valid JSON and says so.
  expect_error(world_with(R"({"type": "box", "min": [NaN,0,0], "max": [1,2,3]})"),
               "not valid JSON");
}

TEST(World, ShippedSampleWorldsLoad) {
  for (const auto& entry :
       std::filesystem::directory_iterator(SCANPLAN_SOURCE_DIR "/samples/worlds")) {
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(load_world(entry.path()));
  }
}

}  // namespace
}  // namespace scanplan

// The object types, grounds and target regions of the world file beyond plain boxes.
#include <gtest/gtest.h>

#include <cmath>

#include "scanplan/sim/ray_caster.hpp"
#include "scanplan/sim/world.hpp"

namespace scanplan {
namespace {

std::string world_with(const std::string& objects, const std::string& ground = R"({"z": 0})",
                       const std::string& bounds = R"({"min": [-10, -10], "max": [10, 10]})") {
  return R"({"name": "t", "bounds": )" + bounds + R"(, "ground": )" + ground + R"(, "objects": [)" +
         objects + R"(], "start": [1, 2, 90]})";
}

void expect_error(const std::string& text, const std::string& fragment) {
  try {
    parse_world(text, "test.json");
    FAIL() << "expected a WorldError mentioning '" << fragment << "'";
  } catch (const WorldError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(WorldObjects, ParsesEveryType) {
  const World w = parse_world(world_with(R"(
      {"type": "cylinder", "center": [1, 2], "z": [0, 6], "radius": 0.1, "color": [1, 2, 3]},
      {"type": "ellipsoid", "center": [1, 2, 3], "radii": [1, 2, 0.5]},
      {"type": "tree", "base": [4, 5, 0.5], "trunk_radius": 0.3, "trunk_height": 3,
       "canopy_radii": [3, 3, 2.5], "color": [0, 100, 0], "trunk_color": [90, 60, 30]},
      {"type": "ramp", "min": [0, 0, 0], "max": [4, 2, 0.3], "rise_axis": "y"},
      {"type": "box", "min": [0, 0, 0], "max": [1, 1, 1], "yaw_deg": 45})"),
                              "t.json");
  ASSERT_EQ(w.cylinders.size(), 1u);
  EXPECT_EQ(w.cylinders[0].center, Eigen::Vector2d(1, 2));
  EXPECT_DOUBLE_EQ(w.cylinders[0].z_max, 6.0);
  EXPECT_DOUBLE_EQ(w.cylinders[0].radius_m, 0.1);
  EXPECT_EQ(w.cylinders[0].color, (Rgb{1, 2, 3}));
  ASSERT_EQ(w.ellipsoids.size(), 1u);
  EXPECT_EQ(w.ellipsoids[0].radii, Eigen::Vector3d(1, 2, 0.5));
  ASSERT_EQ(w.trees.size(), 1u);
  EXPECT_EQ(w.trees[0].canopy_center(), Eigen::Vector3d(4, 5, 0.5 + 3 + 2.5));
  EXPECT_EQ(w.trees[0].trunk_color, (Rgb{90, 60, 30}));
  ASSERT_EQ(w.ramps.size(), 1u);
  EXPECT_EQ(w.ramps[0].rise_axis, 1);
  EXPECT_NEAR(w.ramps[0].top_z(1, 1), 0.15, 1e-12);
  EXPECT_EQ(w.boxes.size(), 1u);
  EXPECT_EQ(RayCaster(w).primitive_count(), 6u) << "a tree is a trunk and a canopy";
}

TEST(WorldObjects, ErrorsNameFileObjectTypeAndField) {
  // objects[0] is fine, so each message must name objects[1].
  const auto obj = [](const std::string& o) {
    return world_with(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]}, )" + o);
  };
  expect_error(obj(R"({"type": "cylinder", "center": [0, 0], "z": [0, 1], "radius": 0})"),
               "test.json: objects[1] (cylinder): field 'radius' must be greater than zero");
  expect_error(obj(R"({"type": "cylinder", "center": [0, 0], "z": [1, 0], "radius": 1})"),
               "objects[1] (cylinder): field 'z' must be [bottom, top]");
  expect_error(obj(R"({"type": "cylinder", "center": [0, 0, 0], "z": [0, 1], "radius": 1})"),
               "objects[1] (cylinder): field 'center' must be an array of 2 numbers");
  expect_error(obj(R"({"type": "ellipsoid", "center": [0, 0, 0], "radii": [1, 0, 1]})"),
               "objects[1] (ellipsoid): field 'radii' must hold three numbers greater than zero");
  expect_error(obj(R"({"type": "ellipsoid", "center": [0, 0, 0], "radii": [1, -1, 1]})"),
               "objects[1] (ellipsoid): field 'radii'");
  expect_error(obj(R"({"type": "tree", "base": [0, 0, 0], "trunk_radius": 0.2,
                       "canopy_radii": [1, 1, 1]})"),
               "objects[1] (tree): field 'trunk_height' is missing");
  expect_error(obj(R"({"type": "tree", "base": [0, 0, 0], "trunk_radius": 0.2, "trunk_height": 3,
                       "canopy_radii": [1, 1]})"),
               "objects[1] (tree): field 'canopy_radii' must be an array of 3 numbers");
  expect_error(obj(R"({"type": "tree", "base": [0, 0, 0], "trunk_radius": -0.2,
                       "trunk_height": 3, "canopy_radii": [1, 1, 1]})"),
               "objects[1] (tree): field 'trunk_radius' must be greater than zero");
  expect_error(obj(R"({"type": "tree", "base": [0, 0, 0], "trunk_radius": 0.2, "trunk_height": 3,
                       "canopy_radii": [1, 1, 1], "leaf_color": [0, 1, 0]})"),
               "objects[1] (tree): field 'leaf_color' is not a known field");
  expect_error(obj(R"({"type": "ramp", "min": [0, 0, 0], "max": [1, 1, 1], "rise_axis": "z"})"),
               "objects[1] (ramp): field 'rise_axis' must be \"x\" or \"y\"");
  expect_error(obj(R"({"type": "ramp", "min": [0, 0, 0], "max": [1, 1, 0], "rise_axis": "x"})"),
               "objects[1] (ramp): field 'max' must exceed 'min'");
  expect_error(obj(R"({"type": "ramp", "min": [0, 0, 0], "max": [1, 1, 1]})"),
               "objects[1] (ramp): field 'rise_axis' is missing");
  expect_error(obj(R"({"type": "cone"})"), "objects[1] (cone): field 'type' 'cone' is not a known");
  expect_error(obj(R"({"type": "cylinder", "center": [0, 1e999], "z": [0, 1], "radius": 1})"),
               "not valid JSON");
  expect_error(obj(R"({"type": "ellipsoid", "center": [0, 0, "1"], "radii": [1, 1, 1]})"),
               "objects[1] (ellipsoid): field 'center' must hold finite numbers only");
}

TEST(WorldGround, GridParsesAndStartSitsOnIt) {
  const World w =
      parse_world(world_with("", R"({"grid": {"origin": [0, 0], "cell": 2, "cols": 2, "rows": 2,
                                  "z": [0, 2, 4, 6]}, "color": [1, 1, 1]})"),
                  "t.json");
  ASSERT_TRUE(w.ground_grid);
  EXPECT_EQ(w.ground_grid->cols(), 2);
  EXPECT_EQ(w.ground_color, (Rgb{1, 1, 1}));
  // Start (1, 2): u = 0.5, v = 1 → (4 + 6) / 2.
  EXPECT_NEAR(w.start.z, 5.0, 1e-12);
  EXPECT_NEAR(w.ground_height(1, 1), 3.0, 1e-12);
}

TEST(WorldGround, Errors) {
  const auto grid = [](const std::string& fields) {
    return world_with("", R"({"grid": {)" + fields + "}}");
  };
  expect_error(world_with("", R"({"z": 0, "grid": {}})"),
               "test.json: ground: field 'grid' cannot be combined with 'z'");
  expect_error(world_with("", R"({"color": [1, 1, 1]})"), "ground needs either 'z'");
  expect_error(grid(R"("origin": [0, 0], "cell": 1, "cols": 2, "rows": 2, "z": [0, 0, 0])"),
               "ground: grid: field 'z' must be an array of 4 numbers");
  expect_error(grid(R"("origin": [0, 0], "cell": 0, "cols": 2, "rows": 2, "z": [0, 0, 0, 0])"),
               "ground: grid: field 'cell' must be greater than zero");
  expect_error(grid(R"("origin": [0, 0], "cell": 1, "cols": 1, "rows": 2, "z": [0, 0])"),
               "ground: grid: field 'cols' must be within 2..");
  expect_error(grid(R"("origin": [0, 0], "cell": 1, "cols": 2.5, "rows": 2, "z": [0, 0])"),
               "ground: grid: field 'cols' must be a whole number");
  expect_error(grid(R"("origin": [0], "cell": 1, "cols": 2, "rows": 2, "z": [0, 0, 0, 0])"),
               "ground: grid: field 'origin' must be an array of 2 numbers");
  expect_error(grid(R"("origin": [0, 0], "cell": 1, "cols": 2, "rows": 2, "z": [0, 0, 0, 0],
                       "rotation": 0)"),
               "ground: grid: field 'rotation' is not a known field");
}

TEST(WorldBounds, PolygonRegion) {
  // An L: the square 0..10 without its north-east quarter.
  const World w = parse_world(
      world_with("", R"({"z": 0})",
                 R"({"polygon": [[0, 0], [10, 0], [10, 5], [5, 5], [5, 10], [0, 10]]})"),
      "t.json");
  EXPECT_EQ(w.bounds_polygon.size(), 6u);
  EXPECT_EQ(w.bounds_min, Eigen::Vector2d(0, 0));
  EXPECT_EQ(w.bounds_max, Eigen::Vector2d(10, 10));
  EXPECT_TRUE(w.in_target_region(2, 2));
  EXPECT_TRUE(w.in_target_region(8, 2));
  EXPECT_TRUE(w.in_target_region(2, 8));
  EXPECT_FALSE(w.in_target_region(8, 8)) << "the cut-out quarter";
  EXPECT_FALSE(w.in_target_region(-1, 2));
  EXPECT_TRUE(w.in_target_region(5, 7)) << "on an edge";
  EXPECT_TRUE(w.in_target_region(10, 5)) << "on a corner";

  const World box = parse_world(world_with(""), "t.json");
  EXPECT_TRUE(box.bounds_polygon.empty());
  EXPECT_TRUE(box.in_target_region(10, -10));
  EXPECT_FALSE(box.in_target_region(10.01, 0));
}

TEST(WorldBounds, Errors) {
  const auto bounds = [](const std::string& b) { return world_with("", R"({"z": 0})", b); };
  expect_error(bounds(R"({"polygon": [[0, 0], [1, 0]]})"),
               "bounds: field 'polygon' must be an array of at least 3");
  expect_error(bounds(R"({"polygon": [[0, 0], [1, 0], [2, 0]]})"),
               "field 'polygon' encloses no area");
  expect_error(bounds(R"({"polygon": [[0, 0], [1, 0], [1]]})"),
               "field 'polygon' vertex 2 must be [x, y]");
  expect_error(bounds(R"({"min": [0, 0], "max": [1, 1], "polygon": [[0, 0], [1, 0], [1, 1]]})"),
               "field 'polygon' cannot be combined");
  expect_error(bounds(R"({})"), "bounds needs either 'min' and 'max' or a 'polygon'");
}

TEST(CampusWorld, HoldsWhatTheDesignAsksFor) {
  const World w = load_world(SCANPLAN_SOURCE_DIR "/samples/worlds/campus.json");
  EXPECT_NEAR(w.bounds_max.x() - w.bounds_min.x(), 200, 20);
  EXPECT_NEAR(w.bounds_max.y() - w.bounds_min.y(), 160, 20);
  ASSERT_TRUE(w.ground_grid) << "the slope is a height grid";
  EXPECT_GT(w.ground_grid->max_height() - w.ground_grid->min_height(), 2.0);

  int buildings = 0, cars = 0;
  for (const auto& b : w.boxes) {
    const Eigen::Vector3d size = b.max - b.min;
    if (size.z() >= 14 && size.z() <= 16) ++buildings;
    if (size.z() > 1.2 && size.z() < 1.8 && size.head<2>().maxCoeff() < 5 &&
        size.head<2>().minCoeff() > 1.5)
      ++cars;
  }
  EXPECT_GE(buildings, 4);
  EXPECT_GE(cars, 12);
  int drive_under = 0;
  for (const auto& t : w.trees) drive_under += t.trunk_height_m >= 2.5;
  EXPECT_GE(drive_under, 20);
  ASSERT_FALSE(w.ramps.empty());
  for (const auto& r : w.ramps) {
    const double slope = (r.max.z() - r.min.z()) / (r.max[r.rise_axis] - r.min[r.rise_axis]);
    EXPECT_LE(rad2deg(std::atan(slope)), 10.0) << "a drivable ramp";
  }
  EXPECT_FALSE(w.cylinders.empty());
  EXPECT_FALSE(w.ellipsoids.empty());
  EXPECT_TRUE(w.in_target_region(w.start.x, w.start.y));

  // The start is in the open: straight down lands on the ground, and a horizontal ring of
  // beams at scanner height is clear for 3 m.
  const RayCaster rc(w);
  const Eigen::Vector3d sensor(w.start.x, w.start.y, w.start.z + 1.0);
  const auto down = rc.cast(sensor, {0, 0, -1}, 0, 10);
  ASSERT_TRUE(down);
  EXPECT_NEAR(down->range, 1.0, 1e-9);
  for (int k = 0; k < 36; ++k) {
    const double a = deg2rad(10.0 * k);
    EXPECT_FALSE(rc.cast(sensor, {std::cos(a), std::sin(a), 0}, 0, 3.0)) << "azimuth " << 10 * k;
  }
}

}  // namespace
}  // namespace scanplan

#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "scanplan/sim/ray_caster.hpp"
#include "scanplan/sim/world.hpp"

namespace scanplan {

struct TraversabilityOptions {
  double cell_m = 0.5;
  // Largest height difference between neighbouring cells the robot climbs (paper §3.2: 0.15 m).
  double max_step_m = 0.15;
  double clearance_m = 1.6;    // free height the robot needs above a surface to stand there
  double min_normal_z = 0.85;  // steeper than about 32° is a wall, not a floor
};

// Where a robot can stand and drive in a simulated world, found by probing it with vertical
// rays over the target region: the ground truth that move commands are checked against and
// coverage is measured on. It knows the whole world, so it is never given to the planner.
class WorldTraversability {
 public:
  WorldTraversability(const World& world, const RayCaster& caster,
                      const TraversabilityOptions& options = {});

  int cols() const { return cols_; }
  int rows() const { return rows_; }
  double cell_m() const { return options_.cell_m; }
  std::size_t cell_count() const { return surfaces_.size(); }
  std::optional<std::size_t> cell_of(double x, double y) const;
  Eigen::Vector2d cell_center(std::size_t cell) const;
  // Heights of the surfaces a robot could stand on in `cell`, highest first.
  const std::vector<float>& surfaces(std::size_t cell) const { return surfaces_[cell]; }

  // The drivable region connected to a start position, with path lengths over it.
  struct Reach {
    std::vector<float> z;  // the reached surface per cell, NaN where not reachable
    std::vector<double> distance_m;
    std::vector<std::size_t> path_to(std::size_t cell) const;
    std::vector<std::int64_t> parent;
    bool reachable(std::size_t cell) const { return cell < z.size() && z[cell] == z[cell]; }
  };
  // Throws std::invalid_argument when (x, y, z) is not on a surface of the region.
  Reach reach_from(double x, double y, double z) const;

  // The pose of a robot standing at (x, y) on the surface near height z, facing `yaw`: roll
  // and pitch follow the ground under it (what the inclination sensor measures, paper §4.3).
  Pose standing_pose(double x, double y, double z, double yaw) const;

 private:
  const World& world_;  // must outlive this object
  RayCaster caster_;    // a cheap copy sharing the built structure
  TraversabilityOptions options_;
  int cols_ = 0, rows_ = 0;
  std::vector<std::vector<float>> surfaces_;
};

}  // namespace scanplan

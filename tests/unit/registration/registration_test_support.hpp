#pragma once
// Scenes with known transforms for the registration tests.

#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "scanplan/geometry/point_cloud.hpp"
#include "scanplan/geometry/pose.hpp"

namespace scanplan::test {

struct Errors {
  double metres, degrees;
};

inline Errors error_of(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  const Eigen::Isometry3d e = truth.inverse() * estimate;
  return {e.translation().norm(), rad2deg(Eigen::AngleAxisd(e.linear()).angle())};
}

inline Pose pose(double x, double y, double z, double yaw_deg, double roll_deg = 0,
                 double pitch_deg = 0) {
  Pose p;
  p.x = x;
  p.y = y;
  p.z = z;
  p.yaw = deg2rad(yaw_deg);
  p.roll = deg2rad(roll_deg);
  p.pitch = deg2rad(pitch_deg);
  return p;
}

// A yard of 30 m × 30 m: ground, three buildings facing different ways, a wall and some posts,
// sampled uniformly on every surface with 5 mm noise. Two calls with different seeds give two
// independent samplings of the same surfaces, as two scans would.
inline PointCloud synthetic_yard(std::uint64_t seed, std::size_t points = 40000) {
  struct Quad {
    Eigen::Vector3d corner, u, v;  // the surface corner + a·u + b·v, a, b in [0, 1]
  };
  std::vector<Quad> quads = {{{-15, -15, 0}, {30, 0, 0}, {0, 30, 0}}};
  const auto box = [&](Eigen::Vector3d min, Eigen::Vector3d size, double yaw) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d ex = R * Eigen::Vector3d(size.x(), 0, 0);
    const Eigen::Vector3d ey = R * Eigen::Vector3d(0, size.y(), 0);
    const Eigen::Vector3d ez(0, 0, size.z());
    quads.push_back({min, ex, ez});
    quads.push_back({min + ey, ex, ez});
    quads.push_back({min, ey, ez});
    quads.push_back({min + ex, ey, ez});
    quads.push_back({min + ez, ex, ey});
  };
  box({-12, 4, 0}, {8, 6, 6}, 0.0);
  box({3, 6, 0}, {7, 4, 4}, deg2rad(25));
  box({5, -12, 0}, {5, 9, 8}, deg2rad(-10));
  box({-13, -10, 0}, {12, 0.3, 1.5}, 0.0);                                     // a wall
  for (int k = 0; k < 4; ++k) box({-4.0 + 3 * k, -3, 0}, {0.3, 0.3, 3}, 0.0);  // posts

  std::vector<double> areas;
  for (const auto& q : quads) areas.push_back(q.u.cross(q.v).norm());
  std::mt19937_64 rng(seed);
  std::discrete_distribution<std::size_t> pick(areas.begin(), areas.end());
  std::uniform_real_distribution<double> unit(0, 1);
  std::normal_distribution<double> noise(0, 0.005);
  PointCloud cloud;
  for (std::size_t i = 0; i < points; ++i) {
    const Quad& q = quads[pick(rng)];
    const Eigen::Vector3d p = q.corner + unit(rng) * q.u + unit(rng) * q.v;
    cloud.points.push_back((p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng))).cast<float>());
  }
  return cloud;
}

inline PointCloud moved(const PointCloud& cloud, const Eigen::Isometry3d& T) {
  PointCloud out;
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (const auto& p : cloud.points) out.points.push_back(Tf * p);
  return out;
}

}  // namespace scanplan::test

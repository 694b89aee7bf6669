#include "scanplan/sim/simulated_odometry.hpp"

#include <cmath>

namespace scanplan {

SimulatedOdometry::SimulatedOdometry(const PoseNoise& noise, const Pose& truth, std::uint64_t seed)
    : noise_(noise), rng_(seed), truth_(truth), reported_(truth) {
  if (noise_.model == OdometryModel::kAbsolute) reported_ = absolute(truth);
}

Pose SimulatedOdometry::absolute(const Pose& truth) {
  std::normal_distribution<double> n01(0.0, 1.0);
  Pose p = truth;
  p.x += noise_.xy_sigma_m * n01(rng_);
  p.y += noise_.xy_sigma_m * n01(rng_);
  p.z += noise_.z_sigma_m * n01(rng_);
  p.yaw += deg2rad(noise_.yaw_sigma_deg) * n01(rng_);
  return p;
}

void SimulatedOdometry::moved(const Pose& truth, double path_m) {
  if (noise_.model == OdometryModel::kAbsolute) {
    truth_ = truth;
    reported_ = absolute(truth);
    return;
  }
  // The true move in the frame of the heading it started from, disturbed, and integrated onto
  // the previous report: a heading error turns every later move.
  std::normal_distribution<double> n01(0.0, 1.0);
  const double d = std::max(0.0, path_m);
  const double c0 = std::cos(truth_.yaw), s0 = std::sin(truth_.yaw);
  const double dx = truth.x - truth_.x, dy = truth.y - truth_.y;
  double forward = c0 * dx + s0 * dy;
  double left = -s0 * dx + c0 * dy;
  forward += noise_.xy_drift_fraction * d * n01(rng_);
  left += noise_.xy_drift_fraction * d * n01(rng_);
  const double turn = std::remainder(truth.yaw - truth_.yaw, 2 * M_PI) +
                      deg2rad(noise_.yaw_drift_deg_per_10m) * d / 10.0 * n01(rng_);
  const double rise = truth.z - truth_.z + noise_.z_drift_fraction * d * n01(rng_);

  const double c = std::cos(reported_.yaw), s = std::sin(reported_.yaw);
  Pose next = truth;  // roll and pitch as measured
  next.x = reported_.x + c * forward - s * left;
  next.y = reported_.y + s * forward + c * left;
  next.z = reported_.z + rise;
  next.yaw = std::remainder(reported_.yaw + turn, 2 * M_PI);
  truth_ = truth;
  reported_ = next;
}

}  // namespace scanplan

#include "scanplan/mission/sensor_frame.hpp"

#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace scanplan {
namespace {

// σ never below these in the fit's covariance: exact sensors leave it otherwise singular.
constexpr double kFloorM = 1e-3;
constexpr double kFloorDeg = 1e-3;

double wrapped(double a) {
  return std::remainder(a, 2 * M_PI);
}

}  // namespace

SensorFrame::SensorFrame(PoseNoise noise, std::vector<Pose> reported, std::vector<Pose> placed)
    : noise_(noise), reported_(std::move(reported)), placed_(std::move(placed)) {
  if (reported_.size() != placed_.size()) {
    throw std::invalid_argument("a sensor frame needs one placed pose for each reported one");
  }
  if (!reported_.empty()) refit();
}

void SensorFrame::add(const Pose& reported, const Pose& placed) {
  reported_.push_back(reported);
  placed_.push_back(placed);
  refit();
}

void SensorFrame::refit() {
  const std::size_t n = reported_.size();
  const double inv_xy = 1.0 / (noise_.xy_sigma_m * noise_.xy_sigma_m);
  const double sigma_yaw = deg2rad(noise_.yaw_sigma_deg);
  const double inv_yaw = 1.0 / (sigma_yaw * sigma_yaw);
  // The yaw readings' mean, unwrapped about the first: where the search starts.
  const double first = wrapped(placed_[0].yaw - reported_[0].yaw);
  double mean = 0;
  for (std::size_t i = 0; i < n; ++i) {
    mean += first + wrapped(placed_[i].yaw - reported_[i].yaw - first);
  }
  mean /= static_cast<double>(n);

  // For a given θ the best t is the mean residual, and the cost is one pass: search θ on a grid
  // wide enough for four sensor σ, then around the best at a finer step.
  const auto fit = [&](double theta, Eigen::Vector2d& t) {
    const Eigen::Matrix2d R = Eigen::Rotation2Dd(theta).toRotationMatrix();
    t.setZero();
    for (std::size_t i = 0; i < n; ++i) {
      t += Eigen::Vector2d(placed_[i].x, placed_[i].y) -
           R * Eigen::Vector2d(reported_[i].x, reported_[i].y);
    }
    t /= static_cast<double>(n);
    double cost = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const Eigen::Vector2d r = Eigen::Vector2d(placed_[i].x, placed_[i].y) -
                                R * Eigen::Vector2d(reported_[i].x, reported_[i].y) - t;
      const double dyaw = wrapped(placed_[i].yaw - reported_[i].yaw - theta);
      cost += r.squaredNorm() * inv_xy + dyaw * dyaw * inv_yaw;
    }
    return cost;
  };
  double best = mean, best_cost = std::numeric_limits<double>::infinity();
  Eigen::Vector2d t;
  const auto search = [&](double centre, double half, double step) {
    const int steps = static_cast<int>(std::ceil(half / step));
    for (int k = -steps; k <= steps; ++k) {
      const double theta = centre + k * step;
      const double cost = fit(theta, t);
      if (cost < best_cost) best_cost = cost, best = theta;
    }
  };
  search(mean, 4 * sigma_yaw, deg2rad(0.05));
  search(best, deg2rad(0.05), deg2rad(0.001));
  yaw_ = best;
  fit(yaw_, t);
  tx_ = t.x();
  ty_ = t.y();
  double dz = 0;
  for (std::size_t i = 0; i < n; ++i) dz += placed_[i].z - reported_[i].z;
  tz_ = dz / static_cast<double>(n);

  // The fit's covariance, linearised at its optimum: each position turns with θ about the sensor
  // frame's origin and moves with t; each yaw reading measures θ. Sure sensors still leave the
  // 3 × 3 system invertible through the floors.
  const double xy2 = std::pow(std::max(noise_.xy_sigma_m, kFloorM), 2);
  const double yaw2 = std::pow(std::max(sigma_yaw, deg2rad(kFloorDeg)), 2);
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Matrix<double, 2, 3> J;
    J.col(0) = turned(reported_[i]);
    J.rightCols<2>().setIdentity();
    information += J.transpose() * J / xy2;
    information(0, 0) += 1 / yaw2;
  }
  covariance_ = information.inverse();
}

// d(R(θ)·r)/dθ at the fitted θ.
Eigen::Vector2d SensorFrame::turned(const Pose& reported) const {
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  return {-s * reported.x - c * reported.y, c * reported.x - s * reported.y};
}

MoveUncertainty SensorFrame::spread(const Pose& reported) const {
  MoveUncertainty own{noise_.xy_sigma_m, noise_.z_sigma_m, noise_.yaw_sigma_deg};
  if (reported_.empty()) return own;
  Eigen::Matrix<double, 2, 3> J;
  J.col(0) = turned(reported);
  J.rightCols<2>().setIdentity();
  const Eigen::Matrix2d position = J * covariance_ * J.transpose();
  // Per axis as the matcher takes it: the frame's worse direction.
  const double frame_xy2 =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(position).eigenvalues()(1);
  const double n = static_cast<double>(reported_.size());
  return {
      std::sqrt(own.xy_m * own.xy_m + std::max(frame_xy2, 0.0)), own.z_m * std::sqrt(1 + 1 / n),
      std::sqrt(own.yaw_deg * own.yaw_deg + std::pow(rad2deg(std::sqrt(covariance_(0, 0))), 2))};
}

Pose SensorFrame::to_map(const Pose& reported) const {
  if (reported_.empty()) return reported;
  Pose p = reported;
  const double c = std::cos(yaw_), s = std::sin(yaw_);
  p.x = c * reported.x - s * reported.y + tx_;
  p.y = s * reported.x + c * reported.y + ty_;
  p.z = reported.z + tz_;
  p.yaw = wrapped(reported.yaw + yaw_);
  return p;
}

}  // namespace scanplan

#pragma once

// The parameterisation both of our solvers (narrower NDT, line-segment ICP) optimise over: a
// small rigid motion applied on the left of the current transform, p'' = R(ω)·p' + δt, where p'
// is a source point already moved by the current estimate. Re-linearising at δ = 0 after every
// step keeps the derivatives simple and exact at the point where they are used.
//
// Parameters: 6 DOF  [tx ty tz ωx ωy ωz];  4 DOF  [tx ty tz ωz]. Turning only about z on the
// left of Rz(yaw)·Ry(pitch)·Rx(roll) changes yaw and never roll or pitch (paper §4.3).

#include <Eigen/Geometry>
#include <array>
#include <cstdio>
#include <string>
#include <utility>

#include "scanplan/registration/registration_result.hpp"

namespace scanplan::detail {

// "1.25 m": lengths in messages, to three significant digits.
inline std::string metres(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g m", v);
  return buf;
}

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;
template <int N>
using Mat = Eigen::Matrix<double, N, N>;

// The rotation axes the parameters after the translation stand for.
template <int N>
constexpr std::array<int, N - 3> rotation_axes() {
  if constexpr (N == 4) {
    return {2};
  } else {
    return {0, 1, 2};
  }
}

// dp''/dθ at δ = 0: the identity for the translation, e_axis × p for each rotation.
template <int N>
Eigen::Matrix<double, 3, N> point_jacobian(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 3, N> J = Eigen::Matrix<double, 3, N>::Zero();
  J.template leftCols<3>().setIdentity();
  const auto axes = rotation_axes<N>();
  for (int k = 0; k < N - 3; ++k) {
    J.col(3 + k) = Eigen::Vector3d::Unit(axes[k]).cross(p);
  }
  return J;
}

// wᵀ·d²p''/dθ_a dθ_b for the rotation parameters (translation pairs are zero). With
// G_a = [e_a]×, the second derivative is ½(G_a G_b + G_b G_a)·p = ½(e_b p_a + e_a p_b) − δ_ab p,
// so the contraction with w is ½(w_b p_a + w_a p_b) − δ_ab (w·p).
template <int N>
Mat<N - 3> contracted_point_hessian(const Eigen::Vector3d& p, const Eigen::Vector3d& w) {
  Mat<N - 3> H;
  const auto axes = rotation_axes<N>();
  const double wp = w.dot(p);
  for (int i = 0; i < N - 3; ++i) {
    for (int j = 0; j < N - 3; ++j) {
      const int a = axes[i], b = axes[j];
      H(i, j) = 0.5 * (w[b] * p[a] + w[a] * p[b]) - (a == b ? wp : 0.0);
    }
  }
  return H;
}

// T ← [R(ω) | δt] · T.
template <int N>
Eigen::Isometry3d apply_increment(const Eigen::Isometry3d& T, const Vec<N>& delta) {
  Eigen::Vector3d omega = Eigen::Vector3d::Zero();
  const auto axes = rotation_axes<N>();
  for (int k = 0; k < N - 3; ++k) omega[axes[k]] = delta[3 + k];
  Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
  const double angle = omega.norm();
  if (angle > 0) step.linear() = Eigen::AngleAxisd(angle, omega / angle).toRotationMatrix();
  step.translation() = delta.template head<3>();
  Eigen::Isometry3d out = step * T;
  // Re-orthonormalise: thousands of small products would otherwise let R drift off SO(3).
  out.linear() = Eigen::Quaterniond(out.linear()).normalized().toRotationMatrix();
  return out;
}

// The size of a step, for convergence tests: translation norm and rotation angle.
template <int N>
std::pair<double, double> step_size(const Vec<N>& delta) {
  return {delta.template head<3>().norm(), delta.template tail<N - 3>().norm()};
}

// Calls f.template operator()<N>() with N = 4 or 6 for the given DOF.
template <typename F>
decltype(auto) with_dof(Dof dof, F&& f) {
  if (dof == Dof::k4) return f.template operator()<4>();
  return f.template operator()<6>();
}

}  // namespace scanplan::detail

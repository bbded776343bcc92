#pragma once
/// @file numeric_jacobian.h
/// Central-difference Jacobians for checking analytic ones (every analytic
/// Jacobian in evio has a test that uses this).

#include <Eigen/Core>

namespace evio::test {

/// J(i, j) = ∂f_i/∂x_j by central differences with step h:
///   (f(x + h e_j) - f(x - h e_j)) / (2h); truncation error O(h²).
/// `f` maps Eigen::Matrix<double, N, 1> to Eigen::Matrix<double, M, 1>.
template <int M, int N, class F>
Eigen::Matrix<double, M, N> numericJacobian(F&& f, const Eigen::Matrix<double, N, 1>& x,
                                            double h = 1e-6) {
  Eigen::Matrix<double, M, N> J;
  for (int j = 0; j < N; ++j) {
    Eigen::Matrix<double, N, 1> xp = x, xm = x;
    xp(j) += h;
    xm(j) -= h;
    J.col(j) = (f(xp) - f(xm)) / (2.0 * h);
  }
  return J;
}

}  // namespace evio::test

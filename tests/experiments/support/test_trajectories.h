#pragma once
/// @file test_trajectories.h
/// Ground-truth trajectories with closed-form poses for the metric tests.

#include <cmath>

#include "evio/core/pose.h"
#include "evio/core/so3.h"

namespace evio::test {

/// A 3D Lissajous-like curve with varying attitude, sampled every dt_s for
/// duration_s (positions span all three axes, so every alignment is determined).
inline Trajectory wavyTrajectory(double duration_s = 20.0, double dt_s = 0.01) {
  Trajectory out;
  const auto n = static_cast<int>(std::llround(duration_s / dt_s));
  for (int k = 0; k <= n; ++k) {
    const double t = k * dt_s;
    const Vec3 p(3.0 * std::sin(0.3 * t), 2.0 * std::sin(0.5 * t + 0.4), 1.0 + 0.5 * std::sin(0.7 * t));
    const Vec3 phi(0.2 * std::sin(0.9 * t), 0.15 * std::cos(0.6 * t), 0.8 * std::sin(0.25 * t));
    out.push_back({secondsToNs(t), Pose(so3::exp(phi), p)});
  }
  return out;
}

/// A straight line along W's x axis at speed_mps with constant attitude R.
inline Trajectory straightLine(double duration_s, double dt_s, double speed_mps,
                               const Mat3& R = Mat3::Identity()) {
  Trajectory out;
  const auto n = static_cast<int>(std::llround(duration_s / dt_s));
  for (int k = 0; k <= n; ++k) {
    const double t = k * dt_s;
    out.push_back({secondsToNs(t), Pose(R, Vec3(speed_mps * t, 0.0, 0.0))});
  }
  return out;
}

}  // namespace evio::test

#pragma once
/// @file helicopter_attitude.h
/// Attitude of a rotorcraft that follows a prescribed path (private to the
/// module): the thrust axis z_B is aligned with the specific force the
/// rotors must produce, z_B ∥ a_W − g_W = a_W + g e_z (differential flatness
/// of multirotors, Mellinger & Kumar 2011), and B's x axis lies in the
/// vertical plane of the heading ψ:
///   y_B = normalize(z_B × (cos ψ, sin ψ, 0)),  x_B = y_B × z_B,
///   R_W_B = [x_B y_B z_B].
/// ω_B needs the jerk and α_B the snap, so the path is a series of order 4
/// and the attitude one of order 2.

#include <cmath>
#include <cstdio>
#include <string>

#include "evio/core/options.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/taylor.h"

namespace evio::preset {

/// Rotors push, never pull: a vertical smoothstep move of `height_m` over
/// `duration_s` must keep its peak acceleration |height|·S''max/T² below
/// gravity, or the thrust a_W + g e_z would point down and the
/// thrust-aligned attitude would flip upside down. Names `field` otherwise.
inline void requireUpwardThrust(const std::string& field, double height_m, double duration_s, double gravity_mps2) {
  const double peak = std::abs(height_m) * motion::kSmoothStepPeakSecondDerivative / (duration_s * duration_s);
  const double shortest = std::sqrt(std::abs(height_m) * motion::kSmoothStepPeakSecondDerivative / gravity_mps2);
  const auto num = [](double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.3g", v);
    return std::string(buf);
  };
  requireField(peak < gravity_mps2, field,
               "a vertical move of " + num(std::abs(height_m)) + " m in " + num(duration_s) + " s peaks at " +
                   num(peak) + " m/s^2, not below gravity (" + num(gravity_mps2) +
                   " m/s^2): the rotors would have to pull down; make it longer than " + num(shortest) + " s");
}

/// R_W_B of order 2 from the acceleration series a_W (order 2: a, jerk/1!, snap/2!).
inline taylor::Matrix3<2> thrustAlignedAttitude(const taylor::Vector3<2>& a_W, double gravity_mps2,
                                                double heading_rad) {
  const taylor::Vector3<2> thrust = a_W + Vec3(0.0, 0.0, gravity_mps2);
  const taylor::Vector3<2> z = taylor::normalized(thrust);
  const auto heading =
      taylor::Vector3<2>::constant(Vec3(std::cos(heading_rad), std::sin(heading_rad), 0.0));
  const taylor::Vector3<2> y = taylor::normalized(taylor::cross(z, heading));
  const taylor::Vector3<2> x = taylor::cross(y, z);
  return taylor::fromColumns(x, y, z);
}

}  // namespace evio::preset

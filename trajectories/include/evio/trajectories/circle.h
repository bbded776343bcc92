#pragma once
/// @file circle.h
/// `circle`: the hand-held circle of the paper's JPL Mars Yard sequence — a
/// horizontal circle of 1.5 m diameter over the ground (and over a sharp
/// shadow), started from hover, with the speed rising every revolution.
///
/// Position:  p_W(t) = center + r (cos θ(t), sin θ(t), 0) + h(t) e_z with
///            θ(t) = θ0 + 2π (f0 t + (f1 − f0) t² / (2T)), the revolution
///            rate ramping linearly from f0 to f1 (speed 2π r f); h a bounded
///            vertical wobble |h| ≤ vertical_wobble_m.
/// Attitude:  R_W_B = Rz(heading + yaw) Ry(pitch) Rx(roll), the angles bounded
///            hand wobbles (the heading does not follow the circle).

#include <array>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct CircleOptions : TrajectoryCommonOptions {
  CircleOptions() { type = "circle"; }

  /// Centre of the circle in W, m (hand-held about 1 m above the ground at z = 0).
  Vec3 center_m = Vec3(0.0, 0.0, 1.0);
  /// Circle diameter, m (Mars Yard sequence: 1.5 m).
  double diameter_m = 1.5;
  /// Revolution rate at the start and at the end, revolutions per second.
  double frequency_start_hz = 0.05;
  double frequency_end_hz = 0.30;
  /// Angle of the start point on the circle from W's x axis, degrees.
  double start_angle_deg = 0.0;
  /// Heading of B's x axis about W's z, degrees (fixed: the camera is carried
  /// around the circle without turning).
  double heading_deg = 0.0;
  /// Bound of the vertical hand wobble, m.
  double vertical_wobble_m = 0.02;
  /// Bounds of the attitude hand wobble (roll, pitch, yaw), degrees.
  Vec3 wobble_amplitude_deg = Vec3(2.0, 2.0, 2.0);
  /// Frequency band of the wobbles, Hz.
  double wobble_min_frequency_hz = 0.2;
  double wobble_max_frequency_hz = 1.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("center_m", center_m, "centre of the circle in W, m");
    v("diameter_m", diameter_m, "circle diameter, m");
    v("frequency_start_hz", frequency_start_hz, "revolutions per second at the start");
    v("frequency_end_hz", frequency_end_hz, "revolutions per second at the end");
    v("start_angle_deg", start_angle_deg, "start angle on the circle from W's x axis, deg");
    v("heading_deg", heading_deg, "fixed heading of B about W's z, deg");
    v("vertical_wobble_m", vertical_wobble_m, "bound of the vertical hand wobble, m");
    v("wobble_amplitude_deg", wobble_amplitude_deg, "roll, pitch, yaw wobble bounds, deg");
    v("wobble_min_frequency_hz", wobble_min_frequency_hz, "lowest wobble frequency, Hz");
    v("wobble_max_frequency_hz", wobble_max_frequency_hz, "highest wobble frequency, Hz");
  }
  void validate() const;
};

class CircleTrajectory final : public ContinuousTrajectory {
 public:
  explicit CircleTrajectory(const CircleOptions& options);
  std::string configYaml() const override;
  const CircleOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  CircleOptions options_;
  motion::Wobble vertical_;
  std::array<motion::Wobble, 3> wobble_;  // roll, pitch, yaw
};

}  // namespace evio

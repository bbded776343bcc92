#pragma once
/// @file hover.h
/// `hover`: a helicopter keeping station. The body drifts slowly inside a box
/// around `center_m` and its attitude wobbles by a few degrees; optionally a
/// large roll/pitch oscillation sets in, as on Ingenuity's sixth flight where
/// an image-timestamp anomaly caused roll and pitch oscillations beyond 20°
/// (Grip et al. 2021).
///
/// Position:  p_W(t) = center + diag(drift_amplitude_m) · w_p(t), each
///            component of w_p a bounded wobble with |w| ≤ 1, so the body
///            never leaves the box center ± drift_amplitude_m.
/// Attitude:  R_W_B = Rz(heading + yaw) Ry(pitch) Rx(roll) with
///            roll  = A_r w_r(t) + E(t) A_o sin(2π f_o t + φ),
///            pitch = A_p w_p(t) + E(t) A_o cos(2π f_o t + φ),
///            yaw   = A_y w_y(t),
///            E(t) = smoothstep((t − oscillation_start_s)/oscillation_ramp_s).

#include <array>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct HoverOptions : TrajectoryCommonOptions {
  HoverOptions() { type = "hover"; }

  /// Station-keeping point of B in W, m (Ingenuity hovered around 10 m).
  Vec3 center_m = Vec3(0.0, 0.0, 10.0);
  /// Heading (yaw of B's x axis from W's x axis, about z), degrees.
  double heading_deg = 0.0;
  /// Half-size of the drift box per W axis, m: |p − center| ≤ this, per axis.
  Vec3 drift_amplitude_m = Vec3(0.25, 0.25, 0.10);
  /// Frequency band of the slow drift, Hz.
  double drift_min_frequency_hz = 0.01;
  double drift_max_frequency_hz = 0.05;
  /// Attitude wobble bounds (roll, pitch, yaw), degrees.
  Vec3 wobble_amplitude_deg = Vec3(3.0, 3.0, 2.0);
  /// Frequency band of the wobble, Hz.
  double wobble_min_frequency_hz = 0.2;
  double wobble_max_frequency_hz = 1.0;
  /// Large roll/pitch oscillation amplitude, degrees; 0 disables it, 25
  /// reproduces the >20° oscillations of Ingenuity's sixth flight.
  double oscillation_amplitude_deg = 0.0;
  /// Frequency of the large oscillation, Hz.
  double oscillation_frequency_hz = 0.5;
  /// Onset of the large oscillation, s after the start, and its smooth ramp-in, s.
  double oscillation_start_s = 20.0;
  double oscillation_ramp_s = 3.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("center_m", center_m, "station-keeping point of B in W, m");
    v("heading_deg", heading_deg, "heading of B's x axis about W's z, deg");
    v("drift_amplitude_m", drift_amplitude_m, "half-size of the drift box per axis, m");
    v("drift_min_frequency_hz", drift_min_frequency_hz, "lowest drift frequency, Hz");
    v("drift_max_frequency_hz", drift_max_frequency_hz, "highest drift frequency, Hz");
    v("wobble_amplitude_deg", wobble_amplitude_deg, "roll, pitch, yaw wobble bounds, deg");
    v("wobble_min_frequency_hz", wobble_min_frequency_hz, "lowest wobble frequency, Hz");
    v("wobble_max_frequency_hz", wobble_max_frequency_hz, "highest wobble frequency, Hz");
    v("oscillation_amplitude_deg", oscillation_amplitude_deg, "large roll/pitch oscillation, deg (0 = off)");
    v("oscillation_frequency_hz", oscillation_frequency_hz, "large oscillation frequency, Hz");
    v("oscillation_start_s", oscillation_start_s, "onset of the large oscillation, s");
    v("oscillation_ramp_s", oscillation_ramp_s, "ramp-in of the large oscillation, s");
  }
  void validate() const;
};

class HoverTrajectory final : public ContinuousTrajectory {
 public:
  explicit HoverTrajectory(const HoverOptions& options);
  std::string configYaml() const override;
  const HoverOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  HoverOptions options_;
  std::array<motion::Wobble, 3> drift_;
  std::array<motion::Wobble, 3> wobble_;  // roll, pitch, yaw
  double oscillation_phase_rad_ = 0.0;
};

}  // namespace evio

#pragma once
/// @file rotation_only.h
/// `rotation_only`: the hand-held shaking of the Event-Camera Dataset's
/// rotation sequences (boxes/poster/shapes/dynamic_rotation): the camera
/// stays in place (translation exactly zero) and is rotated back and forth
/// about all three axes with amplitude and frequency ramping up over the
/// sequence, reaching peak rates of several hundred deg/s.
///
/// Position:  p_W(t) = position_m exactly (all derivatives zero).
/// Attitude:  R_W_B = Rz(heading + yaw) Ry(pitch) Rx(roll), each angle a chirp
///            (motion_primitives.h) A_i(t) sin(Φ_i(t) + φ_i) whose amplitude
///            ramps linearly from amplitude_start_deg to amplitude_end_deg and
///            whose frequency ramps linearly from m_i·frequency_start_hz to
///            m_i·frequency_end_hz; m_i is drawn in [1 − spread, 1 + spread]
///            and φ_i in [0, 2π) so the axes do not move in lockstep.
///            Peak rate about axis i ≈ A_i,end · 2π m_i f_end.

#include <array>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct RotationOnlyOptions : TrajectoryCommonOptions {
  RotationOnlyOptions() {
    type = "rotation_only";
    gravity_mps2 = 9.81;  // an Event-Camera Dataset analogue: recorded on Earth
  }

  /// Fixed position of B in W, m.
  Vec3 position_m = Vec3(0.0, 0.0, 0.0);
  /// Mean heading of B's x axis about W's z, degrees (the scene stands along it).
  double heading_deg = 0.0;
  /// Amplitude (roll, pitch, yaw) at the start and at the end, degrees.
  Vec3 amplitude_start_deg = Vec3(5.0, 5.0, 5.0);
  Vec3 amplitude_end_deg = Vec3(25.0, 25.0, 30.0);
  /// Oscillation frequency at the start and at the end, Hz.
  double frequency_start_hz = 0.3;
  double frequency_end_hz = 3.0;
  /// Relative spread of the per-axis frequency multipliers, in [0, 0.5].
  double frequency_spread = 0.2;
  /// Fade-in from rest over [0, onset_s] (C∞ smoothstep on every axis), s; 0 = none.
  double onset_s = 0.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("position_m", position_m, "fixed position of B in W, m");
    v("heading_deg", heading_deg, "mean heading of B about W's z, deg");
    v("amplitude_start_deg", amplitude_start_deg, "roll, pitch, yaw amplitude at the start, deg");
    v("amplitude_end_deg", amplitude_end_deg, "roll, pitch, yaw amplitude at the end, deg");
    v("frequency_start_hz", frequency_start_hz, "oscillation frequency at the start, Hz");
    v("frequency_end_hz", frequency_end_hz, "oscillation frequency at the end, Hz");
    v("frequency_spread", frequency_spread, "relative spread of per-axis frequencies");
    v("onset_s", onset_s, "fade-in from rest, s (0 = none)");
  }
  void validate() const;
};

class RotationOnlyTrajectory final : public ContinuousTrajectory {
 public:
  explicit RotationOnlyTrajectory(const RotationOnlyOptions& options);
  std::string configYaml() const override;
  const RotationOnlyOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  RotationOnlyOptions options_;
  std::array<motion::Chirp, 3> angle_;  // roll, pitch, yaw
};

}  // namespace evio

#pragma once
/// @file hand_held.h
/// `six_dof` and `translation`: the hand-held motions of the Event-Camera
/// Dataset's 6-DOF and translation sequences (boxes/poster/shapes/dynamic),
/// performed in front of a scene (which stands along the heading) with the
/// speed ramping up over about a minute. `six_dof` excites all six degrees
/// of freedom; `translation` mostly translates, with small rotations.
///
/// Position:  p_W(t) = center + Σ_i e_i x_i(t), each x_i a chirp
///            (motion_primitives.h) with amplitude ramping linearly from
///            translation_amplitude_start_m(i) to translation_amplitude_end_m(i)
///            and frequency from m_i f0 to m_i f1.
/// Attitude:  R_W_B = Rz(heading + yaw) Ry(pitch) Rx(roll), each angle a chirp
///            with rotation_amplitude_*_deg and its own multiplier m'_i.
/// The multipliers are drawn in [1 − spread, 1 + spread], phases in [0, 2π).

#include <array>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

/// Options of `six_dof` (these defaults) and `translation` (TranslationOptions).
struct HandHeldOptions : TrajectoryCommonOptions {
  HandHeldOptions() {
    type = "six_dof";
    gravity_mps2 = 9.81;  // an Event-Camera Dataset analogue: recorded on Earth
  }

  /// Mean position of B in W, m.
  Vec3 center_m = Vec3(0.0, 0.0, 0.0);
  /// Mean heading of B's x axis about W's z, degrees (the scene stands along it).
  double heading_deg = 0.0;
  /// Translation amplitude per W axis at the start and at the end, m.
  Vec3 translation_amplitude_start_m = Vec3(0.03, 0.05, 0.05);
  Vec3 translation_amplitude_end_m = Vec3(0.15, 0.25, 0.20);
  /// Rotation amplitude (roll, pitch, yaw) at the start and at the end, degrees.
  Vec3 rotation_amplitude_start_deg = Vec3(3.0, 3.0, 3.0);
  Vec3 rotation_amplitude_end_deg = Vec3(20.0, 20.0, 30.0);
  /// Oscillation frequency at the start and at the end, Hz.
  double frequency_start_hz = 0.3;
  double frequency_end_hz = 1.2;
  /// Relative spread of the per-axis frequency multipliers, in [0, 0.5].
  double frequency_spread = 0.2;
  /// Fade-in from rest over [0, onset_s] (C∞ smoothstep on every axis), s; 0 = none.
  double onset_s = 0.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("center_m", center_m, "mean position of B in W, m");
    v("heading_deg", heading_deg, "mean heading of B about W's z, deg");
    v("translation_amplitude_start_m", translation_amplitude_start_m, "per-axis amplitude at the start, m");
    v("translation_amplitude_end_m", translation_amplitude_end_m, "per-axis amplitude at the end, m");
    v("rotation_amplitude_start_deg", rotation_amplitude_start_deg, "roll, pitch, yaw amplitude at the start, deg");
    v("rotation_amplitude_end_deg", rotation_amplitude_end_deg, "roll, pitch, yaw amplitude at the end, deg");
    v("frequency_start_hz", frequency_start_hz, "oscillation frequency at the start, Hz");
    v("frequency_end_hz", frequency_end_hz, "oscillation frequency at the end, Hz");
    v("frequency_spread", frequency_spread, "relative spread of per-axis frequencies");
    v("onset_s", onset_s, "fade-in from rest, s (0 = none)");
  }
  void validate() const;
};

/// `translation`: larger translations, rotations of a few degrees.
struct TranslationOptions : HandHeldOptions {
  TranslationOptions() {
    type = "translation";
    translation_amplitude_start_m = Vec3(0.05, 0.08, 0.06);
    translation_amplitude_end_m = Vec3(0.20, 0.35, 0.25);
    rotation_amplitude_start_deg = Vec3(1.0, 1.0, 1.0);
    rotation_amplitude_end_deg = Vec3(4.0, 4.0, 5.0);
  }
};

class HandHeldTrajectory final : public ContinuousTrajectory {
 public:
  explicit HandHeldTrajectory(const HandHeldOptions& options);
  std::string configYaml() const override;
  const HandHeldOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  HandHeldOptions options_;
  std::array<motion::Chirp, 3> translation_;  // x, y, z of W
  std::array<motion::Chirp, 3> rotation_;     // roll, pitch, yaw
};

}  // namespace evio

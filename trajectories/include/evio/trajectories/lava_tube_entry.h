#pragma once
/// @file lava_tube_entry.h
/// `lava_tube_entry`: a helicopter flies from sunlight into the mouth of a
/// lava tube — the paper's mission scenario. It hovers outside in the sun,
/// flies along the tube's axis while descending from its cruise altitude to
/// the altitude it keeps inside, passes the mouth (the shadow line) and stops
/// to hover in the dark.
///
/// Frame: the tube's axis leaves `entrance_m` (the floor point on the axis at
/// the mouth) along the heading ψ, d = (cos ψ, sin ψ, 0); the mouth is at
/// along-axis coordinate 0, outside is negative.
/// Position:  p_W(t) = entrance + s(t) d + h(t) e_z with
///            s = −start_distance + (start_distance + inside_distance) S_entry(t),
///            h = start_altitude + (inside_altitude − start_altitude) S_descent(t);
///            both start at hover_start_s; the descent (descent_s ≤ entry_s)
///            ends before the mouth is reached with the defaults.
/// Attitude:  thrust-aligned with heading ψ (src/helicopter_attitude.h) times a
///            bounded wobble Rz Ry Rx.

#include <array>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct LavaTubeEntryOptions : TrajectoryCommonOptions {
  LavaTubeEntryOptions() { type = "lava_tube_entry"; }

  /// Floor point on the tube's axis at the mouth, m.
  Vec3 entrance_m = Vec3(0.0, 0.0, 0.0);
  /// Direction into the tube (and heading of B), degrees about W's z.
  double tube_heading_deg = 0.0;
  /// Start: distance before the mouth along the axis, m, and height above the floor level, m.
  double start_distance_m = 20.0;
  double start_altitude_m = 8.0;
  /// End: distance inside the mouth along the axis, m, and height above the floor, m.
  double inside_distance_m = 15.0;
  double inside_altitude_m = 2.5;
  /// Hover in the sun before the entry, s.
  double hover_start_s = 5.0;
  /// Duration of the flight along the axis, s; the rest of duration_s is hover inside.
  double entry_s = 30.0;
  /// Duration of the descent to inside_altitude_m, from the start of the entry, s.
  double descent_s = 15.0;
  /// Bounds of the attitude wobble (roll, pitch, yaw), degrees.
  Vec3 wobble_amplitude_deg = Vec3(1.0, 1.0, 1.0);
  /// Frequency band of the wobble, Hz.
  double wobble_min_frequency_hz = 0.2;
  double wobble_max_frequency_hz = 1.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("entrance_m", entrance_m, "floor point on the tube axis at the mouth, m");
    v("tube_heading_deg", tube_heading_deg, "direction into the tube, deg about W's z");
    v("start_distance_m", start_distance_m, "start distance before the mouth, m");
    v("start_altitude_m", start_altitude_m, "start height above the floor level, m");
    v("inside_distance_m", inside_distance_m, "end distance inside the mouth, m");
    v("inside_altitude_m", inside_altitude_m, "height above the floor inside, m");
    v("hover_start_s", hover_start_s, "hover in the sun before the entry, s");
    v("entry_s", entry_s, "duration of the flight along the axis, s");
    v("descent_s", descent_s, "duration of the descent from the start of the entry, s");
    v("wobble_amplitude_deg", wobble_amplitude_deg, "roll, pitch, yaw wobble bounds, deg");
    v("wobble_min_frequency_hz", wobble_min_frequency_hz, "lowest wobble frequency, Hz");
    v("wobble_max_frequency_hz", wobble_max_frequency_hz, "highest wobble frequency, Hz");
  }
  void validate() const;
};

class LavaTubeEntryTrajectory final : public ContinuousTrajectory {
 public:
  explicit LavaTubeEntryTrajectory(const LavaTubeEntryOptions& options);
  std::string configYaml() const override;
  const LavaTubeEntryOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  LavaTubeEntryOptions options_;
  motion::Transition entry_, descent_;
  std::array<motion::Wobble, 3> wobble_;  // roll, pitch, yaw
};

}  // namespace evio

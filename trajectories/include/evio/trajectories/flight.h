#pragma once
/// @file flight.h
/// `flight`: a helicopter flight — rest on the ground, vertical take-off and
/// climb, hover, straight traverse at altitude, hover, vertical descent and
/// landing, rest. Each move is a C∞ smoothstep (motion_primitives.h), so the
/// body stops at the end of every phase.
///
/// Position:  p_W(t) = start + x(t) (cos ψ, sin ψ, 0) + z(t) e_z with
///            z = altitude·(S_climb(t) − S_descent(t)), x = distance·S_traverse(t).
/// Attitude:  thrust-aligned (z_B ∥ a_W − g_W, x_B in the heading plane; see
///            src/helicopter_attitude.h) times a hand-off wobble
///            Rz(yaw) Ry(pitch) Rx(roll) whose bounds scale with the airborne
///            envelope S_climb − S_descent (no wobble on the ground).
/// Phases (s):  ground_time_s, climb_s, hover_before_traverse_s, traverse_s,
///              hover (the remainder of duration_s), descent_s, ground_time_s.

#include <array>

#include "evio/core/eigen_types.h"
#include "evio/trajectories/continuous_trajectory.h"
#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/trajectory_options.h"

namespace evio {

struct FlightOptions : TrajectoryCommonOptions {
  FlightOptions() { type = "flight"; }

  /// Position of B on the ground before take-off, m.
  Vec3 start_m = Vec3(0.0, 0.0, 0.0);
  /// Heading of the traverse and of B's x axis, degrees about W's z.
  double heading_deg = 0.0;
  /// Climb height above the start, m.
  double altitude_m = 10.0;
  /// Length of the straight traverse, m.
  double traverse_distance_m = 50.0;
  /// Rest on the ground before take-off and after landing, s (each).
  double ground_time_s = 2.0;
  /// Durations of the climb, the hover before the traverse, the traverse and
  /// the descent, s. The hover after the traverse takes what remains.
  double climb_s = 8.0;
  double hover_before_traverse_s = 3.0;
  double traverse_s = 20.0;
  double descent_s = 10.0;
  /// Bounds of the airborne attitude wobble (roll, pitch, yaw), degrees.
  Vec3 wobble_amplitude_deg = Vec3(1.0, 1.0, 1.0);
  /// Frequency band of the wobble, Hz.
  double wobble_min_frequency_hz = 0.2;
  double wobble_max_frequency_hz = 1.0;

  template <class V>
  void fields(V& v) {
    commonFields(v);
    v("start_m", start_m, "position of B on the ground before take-off, m");
    v("heading_deg", heading_deg, "heading of the traverse and of B, deg");
    v("altitude_m", altitude_m, "climb height above the start, m");
    v("traverse_distance_m", traverse_distance_m, "length of the traverse, m");
    v("ground_time_s", ground_time_s, "rest before take-off and after landing, s (each)");
    v("climb_s", climb_s, "duration of the climb, s");
    v("hover_before_traverse_s", hover_before_traverse_s, "hover between climb and traverse, s");
    v("traverse_s", traverse_s, "duration of the traverse, s");
    v("descent_s", descent_s, "duration of the descent, s");
    v("wobble_amplitude_deg", wobble_amplitude_deg, "airborne roll, pitch, yaw wobble bounds, deg");
    v("wobble_min_frequency_hz", wobble_min_frequency_hz, "lowest wobble frequency, Hz");
    v("wobble_max_frequency_hz", wobble_max_frequency_hz, "highest wobble frequency, Hz");
  }
  void validate() const;
  /// Hover after the traverse: duration_s minus every other phase, s.
  double finalHoverSeconds() const;
};

class FlightTrajectory final : public ContinuousTrajectory {
 public:
  explicit FlightTrajectory(const FlightOptions& options);
  std::string configYaml() const override;
  const FlightOptions& options() const { return options_; }

 protected:
  Motion motion(double t_s) const override;

 private:
  FlightOptions options_;
  motion::Transition climb_, traverse_, descent_;
  std::array<motion::Wobble, 3> wobble_;  // roll, pitch, yaw
};

}  // namespace evio

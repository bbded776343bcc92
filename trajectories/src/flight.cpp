#include "evio/trajectories/flight.h"

#include "evio/trajectories/taylor_rotation.h"
#include "helicopter_attitude.h"
#include "preset_util.h"

namespace evio {

double FlightOptions::finalHoverSeconds() const {
  return duration_s - (2.0 * ground_time_s + climb_s + hover_before_traverse_s + traverse_s + descent_s);
}

void FlightOptions::validate() const {
  validateCommon("flight");
  preset::requireFinite3("start_m", start_m);
  requirePositive("altitude_m", altitude_m);
  requireNonNegative("traverse_distance_m", traverse_distance_m);
  requireNonNegative("ground_time_s", ground_time_s);
  requirePositive("climb_s", climb_s);
  requireNonNegative("hover_before_traverse_s", hover_before_traverse_s);
  requirePositive("traverse_s", traverse_s);
  requirePositive("descent_s", descent_s);
  requireField(finalHoverSeconds() >= 0.0, "duration_s",
               "must be at least the sum of the phases (" +
                   std::to_string(duration_s - finalHoverSeconds()) + " s)");
  preset::requireUpwardThrust("climb_s", altitude_m, climb_s, gravity_mps2);
  preset::requireUpwardThrust("descent_s", altitude_m, descent_s, gravity_mps2);
  preset::requireNonNegative3("wobble_amplitude_deg", wobble_amplitude_deg);
  requireInRange("wobble_amplitude_deg[1]", wobble_amplitude_deg(1), 0.0, 30.0);
  preset::requireBand("wobble_min_frequency_hz", wobble_min_frequency_hz, "wobble_max_frequency_hz",
                      wobble_max_frequency_hz);
}

FlightTrajectory::FlightTrajectory(const FlightOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  const FlightOptions& o = options_;
  climb_ = {o.ground_time_s, o.climb_s, o.altitude_m};
  traverse_ = {climb_.end_s() + o.hover_before_traverse_s, o.traverse_s, o.traverse_distance_m};
  descent_ = {traverse_.end_s() + o.finalHoverSeconds(), o.descent_s, -o.altitude_m};
  RandomStream rng(o.seed, "trajectory");
  for (auto& w : wobble_) w = motion::Wobble(rng, o.wobble_min_frequency_hz, o.wobble_max_frequency_hz);
}

std::string FlightTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion FlightTrajectory::motion(double t_s) const {
  const FlightOptions& o = options_;
  const double heading = o.heading_deg * preset::kDegToRad;
  const Vec3 dir(std::cos(heading), std::sin(heading), 0.0);

  // Path as an order-4 series: the attitude needs jerk and snap.
  const taylor::Scalar<4> t4 = taylor::variable<4>(t_s);
  const taylor::Vector3<4> p4 = taylor::Vector3<4>::constant(o.start_m) + traverse_(t4) * dir +
                                (climb_(t4) + descent_(t4)) * Vec3::UnitZ().eval();

  Motion m;
  m.p_W = taylor::truncate<2>(p4);
  const taylor::Matrix3<2> R_thrust =
      preset::thrustAlignedAttitude(taylor::differentiate<2>(p4), o.gravity_mps2, heading);

  const taylor::Scalar<2> t = taylor::variable<2>(t_s);
  const taylor::Scalar<2> airborne = (1.0 / o.altitude_m) * (climb_(t) + descent_(t));
  const Vec3 a = o.wobble_amplitude_deg * preset::kDegToRad;
  m.R_W_B = R_thrust * taylor::eulerZYX(a.z() * (airborne * wobble_[2](t)),
                                        a.y() * (airborne * wobble_[1](t)),
                                        a.x() * (airborne * wobble_[0](t)));
  return m;
}

}  // namespace evio

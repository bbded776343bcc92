#include "evio/trajectories/hover.h"

#include "evio/trajectories/taylor_rotation.h"
#include "preset_util.h"

namespace evio {

void HoverOptions::validate() const {
  validateCommon("hover");
  preset::requireFinite3("center_m", center_m);
  preset::requireNonNegative3("drift_amplitude_m", drift_amplitude_m);
  preset::requireBand("drift_min_frequency_hz", drift_min_frequency_hz, "drift_max_frequency_hz",
                      drift_max_frequency_hz);
  preset::requireNonNegative3("wobble_amplitude_deg", wobble_amplitude_deg);
  requireInRange("wobble_amplitude_deg[1]", wobble_amplitude_deg(1), 0.0, 60.0);
  preset::requireBand("wobble_min_frequency_hz", wobble_min_frequency_hz, "wobble_max_frequency_hz",
                      wobble_max_frequency_hz);
  requireInRange("oscillation_amplitude_deg", oscillation_amplitude_deg, 0.0, 45.0);
  requirePositive("oscillation_frequency_hz", oscillation_frequency_hz);
  requireNonNegative("oscillation_start_s", oscillation_start_s);
  requirePositive("oscillation_ramp_s", oscillation_ramp_s);
  requireField(wobble_amplitude_deg(1) + oscillation_amplitude_deg < 80.0, "oscillation_amplitude_deg",
               "pitch wobble plus oscillation must stay below 80 deg");
}

HoverTrajectory::HoverTrajectory(const HoverOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  RandomStream rng(options_.seed, "trajectory");
  for (auto& d : drift_)
    d = motion::Wobble(rng, options_.drift_min_frequency_hz, options_.drift_max_frequency_hz);
  for (auto& w : wobble_)
    w = motion::Wobble(rng, options_.wobble_min_frequency_hz, options_.wobble_max_frequency_hz);
  oscillation_phase_rad_ = rng.uniform(0.0, 2.0 * std::numbers::pi);
}

std::string HoverTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion HoverTrajectory::motion(double t_s) const {
  using S = taylor::Scalar<2>;
  const S t = taylor::variable<2>(t_s);
  const HoverOptions& o = options_;

  Motion m;
  m.p_W = taylor::makeVector(o.center_m.x() + o.drift_amplitude_m.x() * drift_[0](t),
                             o.center_m.y() + o.drift_amplitude_m.y() * drift_[1](t),
                             o.center_m.z() + o.drift_amplitude_m.z() * drift_[2](t));

  const Vec3 a = o.wobble_amplitude_deg * preset::kDegToRad;
  S roll = a.x() * wobble_[0](t);
  S pitch = a.y() * wobble_[1](t);
  const S yaw = o.heading_deg * preset::kDegToRad + a.z() * wobble_[2](t);
  if (o.oscillation_amplitude_deg > 0.0) {
    const S envelope =
        motion::smoothStep((1.0 / o.oscillation_ramp_s) * (t - o.oscillation_start_s));
    const S phase = (2.0 * std::numbers::pi * o.oscillation_frequency_hz) * t + oscillation_phase_rad_;
    S s, c;
    taylor::sinCos(phase, &s, &c);
    const double amp = o.oscillation_amplitude_deg * preset::kDegToRad;
    roll = roll + amp * (envelope * s);
    pitch = pitch + amp * (envelope * c);
  }
  m.R_W_B = taylor::eulerZYX(yaw, pitch, roll);
  return m;
}

}  // namespace evio

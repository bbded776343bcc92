#include "evio/trajectories/rotation_only.h"

#include "evio/trajectories/taylor_rotation.h"
#include "preset_util.h"

namespace evio {

void RotationOnlyOptions::validate() const {
  validateCommon("rotation_only");
  preset::requireFinite3("position_m", position_m);
  preset::requireNonNegative3("amplitude_start_deg", amplitude_start_deg);
  preset::requireNonNegative3("amplitude_end_deg", amplitude_end_deg);
  requireField(amplitude_start_deg.y() < 60.0 && amplitude_end_deg.y() < 60.0, "amplitude_end_deg",
               "pitch amplitude must stay below 60 deg (Euler angles)");
  requirePositive("frequency_start_hz", frequency_start_hz);
  requirePositive("frequency_end_hz", frequency_end_hz);
  requireInRange("frequency_spread", frequency_spread, 0.0, 0.5);
  requireInRange("onset_s", onset_s, 0.0, duration_s);
}

RotationOnlyTrajectory::RotationOnlyTrajectory(const RotationOnlyOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  RandomStream rng(options_.seed, "trajectory");
  for (int i = 0; i < 3; ++i) {
    const double m = rng.uniform(1.0 - options_.frequency_spread, 1.0 + options_.frequency_spread);
    motion::Chirp& c = angle_[static_cast<std::size_t>(i)];
    c.amplitude_start = options_.amplitude_start_deg(i) * preset::kDegToRad;
    c.amplitude_end = options_.amplitude_end_deg(i) * preset::kDegToRad;
    c.frequency_start_hz = m * options_.frequency_start_hz;
    c.frequency_end_hz = m * options_.frequency_end_hz;
    c.duration_s = options_.duration_s;
    c.phase_rad = rng.uniform(0.0, 2.0 * std::numbers::pi);
    c.onset_s = options_.onset_s;
  }
}

std::string RotationOnlyTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion RotationOnlyTrajectory::motion(double t_s) const {
  const taylor::Scalar<2> t = taylor::variable<2>(t_s);
  Motion m;
  m.p_W = taylor::Vector3<2>::constant(options_.position_m);
  m.R_W_B = taylor::eulerZYX(options_.heading_deg * preset::kDegToRad + angle_[2](t), angle_[1](t),
                             angle_[0](t));
  return m;
}

}  // namespace evio

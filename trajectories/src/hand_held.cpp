#include "evio/trajectories/hand_held.h"

#include "evio/trajectories/taylor_rotation.h"
#include "preset_util.h"

namespace evio {

void HandHeldOptions::validate() const {
  requireField(type == "six_dof" || type == "translation", "type", "must be six_dof or translation");
  validateCommon(type);
  preset::requireFinite3("center_m", center_m);
  preset::requireNonNegative3("translation_amplitude_start_m", translation_amplitude_start_m);
  preset::requireNonNegative3("translation_amplitude_end_m", translation_amplitude_end_m);
  preset::requireNonNegative3("rotation_amplitude_start_deg", rotation_amplitude_start_deg);
  preset::requireNonNegative3("rotation_amplitude_end_deg", rotation_amplitude_end_deg);
  requireField(rotation_amplitude_start_deg.y() < 60.0 && rotation_amplitude_end_deg.y() < 60.0,
               "rotation_amplitude_end_deg", "pitch amplitude must stay below 60 deg (Euler angles)");
  requirePositive("frequency_start_hz", frequency_start_hz);
  requirePositive("frequency_end_hz", frequency_end_hz);
  requireInRange("frequency_spread", frequency_spread, 0.0, 0.5);
  requireInRange("onset_s", onset_s, 0.0, duration_s);
}

namespace {

motion::Chirp drawChirp(RandomStream& rng, const HandHeldOptions& o, double a0, double a1) {
  const double m = rng.uniform(1.0 - o.frequency_spread, 1.0 + o.frequency_spread);
  motion::Chirp c;
  c.amplitude_start = a0;
  c.amplitude_end = a1;
  c.frequency_start_hz = m * o.frequency_start_hz;
  c.frequency_end_hz = m * o.frequency_end_hz;
  c.duration_s = o.duration_s;
  c.phase_rad = rng.uniform(0.0, 2.0 * std::numbers::pi);
  c.onset_s = o.onset_s;
  return c;
}

}  // namespace

HandHeldTrajectory::HandHeldTrajectory(const HandHeldOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  RandomStream rng(options_.seed, "trajectory");
  for (int i = 0; i < 3; ++i)
    translation_[static_cast<std::size_t>(i)] = drawChirp(
        rng, options_, options_.translation_amplitude_start_m(i), options_.translation_amplitude_end_m(i));
  for (int i = 0; i < 3; ++i)
    rotation_[static_cast<std::size_t>(i)] =
        drawChirp(rng, options_, options_.rotation_amplitude_start_deg(i) * preset::kDegToRad,
                  options_.rotation_amplitude_end_deg(i) * preset::kDegToRad);
}

std::string HandHeldTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion HandHeldTrajectory::motion(double t_s) const {
  const taylor::Scalar<2> t = taylor::variable<2>(t_s);
  const Vec3& c = options_.center_m;
  Motion m;
  m.p_W = taylor::makeVector(c.x() + translation_[0](t), c.y() + translation_[1](t),
                             c.z() + translation_[2](t));
  m.R_W_B = taylor::eulerZYX(options_.heading_deg * preset::kDegToRad + rotation_[2](t),
                             rotation_[1](t), rotation_[0](t));
  return m;
}

}  // namespace evio

#include "evio/trajectories/circle.h"

#include "evio/trajectories/taylor_rotation.h"
#include "preset_util.h"

namespace evio {

void CircleOptions::validate() const {
  validateCommon("circle");
  preset::requireFinite3("center_m", center_m);
  requirePositive("diameter_m", diameter_m);
  requireNonNegative("frequency_start_hz", frequency_start_hz);
  requireNonNegative("frequency_end_hz", frequency_end_hz);
  requireNonNegative("vertical_wobble_m", vertical_wobble_m);
  preset::requireNonNegative3("wobble_amplitude_deg", wobble_amplitude_deg);
  requireInRange("wobble_amplitude_deg[1]", wobble_amplitude_deg(1), 0.0, 60.0);
  preset::requireBand("wobble_min_frequency_hz", wobble_min_frequency_hz, "wobble_max_frequency_hz",
                      wobble_max_frequency_hz);
}

CircleTrajectory::CircleTrajectory(const CircleOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  RandomStream rng(options_.seed, "trajectory");
  vertical_ = motion::Wobble(rng, options_.wobble_min_frequency_hz, options_.wobble_max_frequency_hz);
  for (auto& w : wobble_)
    w = motion::Wobble(rng, options_.wobble_min_frequency_hz, options_.wobble_max_frequency_hz);
}

std::string CircleTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion CircleTrajectory::motion(double t_s) const {
  using S = taylor::Scalar<2>;
  const S t = taylor::variable<2>(t_s);
  const CircleOptions& o = options_;
  const double r = 0.5 * o.diameter_m;
  const double T = o.duration_s;
  const S theta = o.start_angle_deg * preset::kDegToRad +
                  (2.0 * std::numbers::pi) *
                      (o.frequency_start_hz * t +
                       ((o.frequency_end_hz - o.frequency_start_hz) / (2.0 * T)) * (t * t));
  S s, c;
  taylor::sinCos(theta, &s, &c);
  Motion m;
  m.p_W = taylor::makeVector(o.center_m.x() + r * c, o.center_m.y() + r * s,
                             o.center_m.z() + o.vertical_wobble_m * vertical_(t));
  const Vec3 a = o.wobble_amplitude_deg * preset::kDegToRad;
  m.R_W_B = taylor::eulerZYX(o.heading_deg * preset::kDegToRad + a.z() * wobble_[2](t),
                             a.y() * wobble_[1](t), a.x() * wobble_[0](t));
  return m;
}

}  // namespace evio

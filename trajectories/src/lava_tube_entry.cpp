#include "evio/trajectories/lava_tube_entry.h"

#include "evio/trajectories/taylor_rotation.h"
#include "helicopter_attitude.h"
#include "preset_util.h"

namespace evio {

void LavaTubeEntryOptions::validate() const {
  validateCommon("lava_tube_entry");
  preset::requireFinite3("entrance_m", entrance_m);
  requireNonNegative("start_distance_m", start_distance_m);
  requirePositive("start_altitude_m", start_altitude_m);
  requireNonNegative("inside_distance_m", inside_distance_m);
  requirePositive("inside_altitude_m", inside_altitude_m);
  requireNonNegative("hover_start_s", hover_start_s);
  requirePositive("entry_s", entry_s);
  requirePositive("descent_s", descent_s);
  requireField(descent_s <= entry_s, "descent_s", "must not exceed entry_s");
  requireField(hover_start_s + entry_s <= duration_s, "duration_s",
               "must be at least hover_start_s + entry_s");
  preset::requireUpwardThrust("descent_s", inside_altitude_m - start_altitude_m, descent_s, gravity_mps2);
  preset::requireNonNegative3("wobble_amplitude_deg", wobble_amplitude_deg);
  requireInRange("wobble_amplitude_deg[1]", wobble_amplitude_deg(1), 0.0, 30.0);
  preset::requireBand("wobble_min_frequency_hz", wobble_min_frequency_hz, "wobble_max_frequency_hz",
                      wobble_max_frequency_hz);
}

LavaTubeEntryTrajectory::LavaTubeEntryTrajectory(const LavaTubeEntryOptions& options)
    : ContinuousTrajectory(0, secondsToNs(options.duration_s)), options_(options) {
  options_.validate();
  const LavaTubeEntryOptions& o = options_;
  entry_ = {o.hover_start_s, o.entry_s, o.start_distance_m + o.inside_distance_m};
  descent_ = {o.hover_start_s, o.descent_s, o.inside_altitude_m - o.start_altitude_m};
  RandomStream rng(o.seed, "trajectory");
  for (auto& w : wobble_) w = motion::Wobble(rng, o.wobble_min_frequency_hz, o.wobble_max_frequency_hz);
}

std::string LavaTubeEntryTrajectory::configYaml() const { return preset::yamlOf(options_); }

ContinuousTrajectory::Motion LavaTubeEntryTrajectory::motion(double t_s) const {
  const LavaTubeEntryOptions& o = options_;
  const double heading = o.tube_heading_deg * preset::kDegToRad;
  const Vec3 dir(std::cos(heading), std::sin(heading), 0.0);

  const taylor::Scalar<4> t4 = taylor::variable<4>(t_s);
  const Vec3 start = o.entrance_m - o.start_distance_m * dir + o.start_altitude_m * Vec3::UnitZ();
  const taylor::Vector3<4> p4 = taylor::Vector3<4>::constant(start) + entry_(t4) * dir +
                                descent_(t4) * Vec3::UnitZ().eval();

  Motion m;
  m.p_W = taylor::truncate<2>(p4);
  const taylor::Matrix3<2> R_thrust =
      preset::thrustAlignedAttitude(taylor::differentiate<2>(p4), o.gravity_mps2, heading);
  const taylor::Scalar<2> t = taylor::variable<2>(t_s);
  const Vec3 a = o.wobble_amplitude_deg * preset::kDegToRad;
  m.R_W_B = R_thrust * taylor::eulerZYX(a.z() * wobble_[2](t), a.y() * wobble_[1](t),
                                        a.x() * wobble_[0](t));
  return m;
}

}  // namespace evio

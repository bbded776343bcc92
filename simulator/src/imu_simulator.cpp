#include "evio/simulator/imu_simulator.h"

#include <cmath>

namespace evio {

void ImuSimulator::Options::validate() const {
  requireInRange("update_rate_hz", update_rate_hz, 1.0, 100000.0);
  requireNonNegative("accelerometer_noise_density", accelerometer_noise_density);
  requireNonNegative("accelerometer_random_walk", accelerometer_random_walk);
  requireNonNegative("gyroscope_noise_density", gyroscope_noise_density);
  requireNonNegative("gyroscope_random_walk", gyroscope_random_walk);
  requirePositive("gravity_mps2", gravity_mps2);
  requireField(accelerometer_initial_bias_mps2.allFinite(), "accelerometer_initial_bias_mps2", "must be finite");
  requireField(gyroscope_initial_bias_radps.allFinite(), "gyroscope_initial_bias_radps", "must be finite");
  requireField(accelerometer_scale.allFinite() && (accelerometer_scale.array() > 0).all(),
               "accelerometer_scale", "must be finite and > 0");
  requireField(gyroscope_scale.allFinite() && (gyroscope_scale.array() > 0).all(), "gyroscope_scale",
               "must be finite and > 0");
  requireField(accelerometer_misalignment.allFinite() && accelerometer_misalignment.determinant() > 0.1,
               "accelerometer_misalignment", "must be finite with determinant > 0.1");
  requireField(gyroscope_misalignment.allFinite() && gyroscope_misalignment.determinant() > 0.1,
               "gyroscope_misalignment", "must be finite with determinant > 0.1");
  requireField(accelerometer_saturation_mps2 > 0.0, "accelerometer_saturation_mps2", "must be > 0");
  requireField(gyroscope_saturation_radps > 0.0, "gyroscope_saturation_radps", "must be > 0");
  requireInRange("timeshift_cam_imu_s", timeshift_cam_imu_s, -1.0, 1.0);
}

ImuSample ImuSimulator::ideal(const TrajectoryState& state, double gravity_mps2) {
  ImuSample s;
  s.t_ns = state.t_ns;
  const Vec3 g_W(0.0, 0.0, -gravity_mps2);
  s.acc_B = state.T_W_B.quaternion().conjugate() * (state.a_W - g_W);
  s.gyro_B = state.omega_B;
  return s;
}

ImuSimulator::ImuSimulator(const ContinuousTrajectory& trajectory, const Options& options,
                           std::uint64_t seed)
    : trajectory_(trajectory),
      options_(options),
      accel_noise_(seed, "imu_accel_noise"),
      gyro_noise_(seed, "imu_gyro_noise"),
      accel_bias_rng_(seed, "imu_accel_bias"),
      gyro_bias_rng_(seed, "imu_gyro_bias") {
  options_.validate();
  shift_ns_ = secondsToNs(options_.timeshift_cam_imu_s);
  const double dt = 1.0 / options_.update_rate_hz;
  accel_sigma_ = options_.accelerometer_noise_density / std::sqrt(dt);
  gyro_sigma_ = options_.gyroscope_noise_density / std::sqrt(dt);
  accel_walk_ = options_.accelerometer_random_walk * std::sqrt(dt);
  gyro_walk_ = options_.gyroscope_random_walk * std::sqrt(dt);
  accel_bias_ = options_.accelerometer_initial_bias_mps2;
  gyro_bias_ = options_.gyroscope_initial_bias_radps;
  // Samples k = 0 … count−1 whose true time stays inside the trajectory.
  const TimeNs span = trajectory_.endTime() - trajectory_.startTime();
  std::int64_t k = static_cast<std::int64_t>(std::floor(nsToSeconds(span) * options_.update_rate_hz)) + 1;
  while (k > 0 && stampOf(k - 1) - shift_ns_ > trajectory_.endTime()) --k;
  while (stampOf(k) - shift_ns_ <= trajectory_.endTime()) ++k;
  count_ = k;
}

TimeNs ImuSimulator::stampOf(std::int64_t k) const {
  const double offset_ns = static_cast<double>(k) * 1e9 / options_.update_rate_hz;
  return trajectory_.startTime() + shift_ns_ + static_cast<TimeNs>(std::llround(offset_ns));
}

namespace {

Vec3 standardNormal3(RandomStream& rng) {
  const double x = rng.normal();
  const double y = rng.normal();
  const double z = rng.normal();
  return Vec3(x, y, z);
}

Vec3 saturate(const Vec3& v, double limit) { return v.cwiseMax(-limit).cwiseMin(limit); }

}  // namespace

bool ImuSimulator::next(ImuMeasurement& out) {
  if (k_ >= count_) return false;
  const TimeNs stamp = stampOf(k_);
  if (k_ > 0) {
    accel_bias_ += accel_walk_ * standardNormal3(accel_bias_rng_);
    gyro_bias_ += gyro_walk_ * standardNormal3(gyro_bias_rng_);
  }
  out.truth = trajectory_.evaluate(stamp - shift_ns_);
  out.ideal = ideal(out.truth, options_.gravity_mps2);
  out.ideal.t_ns = stamp;
  out.accel_bias = accel_bias_;
  out.gyro_bias = gyro_bias_;
  const Options& o = options_;
  out.sample.t_ns = stamp;
  out.sample.acc_B = saturate(o.accelerometer_scale.asDiagonal() * (o.accelerometer_misalignment * out.ideal.acc_B) +
                                  accel_bias_ + accel_sigma_ * standardNormal3(accel_noise_),
                              o.accelerometer_saturation_mps2);
  out.sample.gyro_B = saturate(o.gyroscope_scale.asDiagonal() * (o.gyroscope_misalignment * out.ideal.gyro_B) +
                                   gyro_bias_ + gyro_sigma_ * standardNormal3(gyro_noise_),
                               o.gyroscope_saturation_radps);
  ++k_;
  return true;
}

}  // namespace evio

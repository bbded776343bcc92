#pragma once
/// @file imu_simulator.h
/// IMU readings synthesised from a continuous trajectory, streamed one sample
/// at a time (memory stays flat), with the noise model estimators assume
/// (Kalibr's IMU noise model; Furgale et al. 2013, Trawny & Roumeliotis 2005):
///
///   ideal:   a_B = R_W_Bᵀ (a_W − g_W),  g_W = (0, 0, −g);   ω_B from the trajectory.
///   biases:  b_{k} = b_{k−1} + σ_b √Δt · n_k           (random walk, stepped at every sample)
///   reading: y_k = sat( diag(s) · M · ideal_k + b_k + (σ_c / √Δt) · n'_k )
///
/// with n, n' ~ N(0, I₃), σ_c the continuous white-noise density
/// (*_noise_density), σ_b the continuous bias random-walk density
/// (*_random_walk), s per-axis scale factors, M the axis misalignment, and
/// sat a per-axis clamp to ±saturation. Sample 0 carries the initial biases.
/// The four noise sources draw from their own streams: RandomStream(seed,
/// "imu_accel_noise" | "imu_gyro_noise" | "imu_accel_bias" | "imu_gyro_bias").

#include <cstdint>
#include <limits>

#include "evio/core/eigen_types.h"
#include "evio/core/imu_sample.h"
#include "evio/core/options.h"
#include "evio/core/random_stream.h"
#include "evio/trajectories/continuous_trajectory.h"

namespace evio {

/// One synthesised sample with everything that is true about it.
struct ImuMeasurement {
  ImuSample sample;             ///< what the IMU reports, stamped on the IMU clock
  ImuSample ideal;              ///< the ideal reading at the same stamp (no error of any kind)
  TrajectoryState truth;        ///< the true motion at true time sample.t_ns − timeshift
  Vec3 accel_bias = Vec3::Zero();  ///< true accelerometer bias inside `sample`, m/s²
  Vec3 gyro_bias = Vec3::Zero();   ///< true gyroscope bias inside `sample`, rad/s
};

class ImuSimulator {
 public:
  /// Field names follow Kalibr's imu.yaml (with units appended where Kalibr has none).
  struct Options {
    /// Sample rate, Hz (Kalibr `update_rate`). The DAVIS240's IMU runs at 1 kHz.
    double update_rate_hz = 1000.0;
    /// Accelerometer white-noise density σ_c, m/s²/√Hz (DAVIS240 reference: 0.004316).
    double accelerometer_noise_density = 0.004316;
    /// Accelerometer bias random-walk density σ_b, m/s³/√Hz.
    double accelerometer_random_walk = 0.0004316;
    /// Gyroscope white-noise density σ_c, rad/s/√Hz.
    double gyroscope_noise_density = 0.0002;
    /// Gyroscope bias random-walk density σ_b, rad/s²/√Hz.
    double gyroscope_random_walk = 0.00002;
    /// Gravity magnitude along −z of W, m/s² (Mars 3.721, Earth 9.81).
    double gravity_mps2 = 3.721;
    /// Biases at the first sample.
    Vec3 accelerometer_initial_bias_mps2 = Vec3::Zero();
    Vec3 gyroscope_initial_bias_radps = Vec3::Zero();
    /// Per-axis scale factors s (1: none).
    Vec3 accelerometer_scale = Vec3::Ones();
    Vec3 gyroscope_scale = Vec3::Ones();
    /// Axis misalignment M (row-major in YAML; identity: none). Row i is the
    /// sensitive axis of sensor axis i expressed in B.
    Mat3 accelerometer_misalignment = Mat3::Identity();
    Mat3 gyroscope_misalignment = Mat3::Identity();
    /// Per-axis saturation of the reading (.inf: none), m/s² and rad/s.
    double accelerometer_saturation_mps2 = std::numeric_limits<double>::infinity();
    double gyroscope_saturation_radps = std::numeric_limits<double>::infinity();
    /// Kalibr `timeshift_cam_imu`: t_imu = t_cam + shift, s. The sample stamped
    /// t reports the motion at true (camera / ground-truth) time t − shift.
    double timeshift_cam_imu_s = 0.0;

    template <class V>
    void fields(V& v) {
      v("update_rate_hz", update_rate_hz, "sample rate, Hz");
      v("accelerometer_noise_density", accelerometer_noise_density, "m/s^2/sqrt(Hz)");
      v("accelerometer_random_walk", accelerometer_random_walk, "m/s^3/sqrt(Hz)");
      v("gyroscope_noise_density", gyroscope_noise_density, "rad/s/sqrt(Hz)");
      v("gyroscope_random_walk", gyroscope_random_walk, "rad/s^2/sqrt(Hz)");
      v("gravity_mps2", gravity_mps2, "gravity magnitude, m/s^2");
      v("accelerometer_initial_bias_mps2", accelerometer_initial_bias_mps2, "initial accelerometer bias");
      v("gyroscope_initial_bias_radps", gyroscope_initial_bias_radps, "initial gyroscope bias");
      v("accelerometer_scale", accelerometer_scale, "per-axis accelerometer scale factors");
      v("gyroscope_scale", gyroscope_scale, "per-axis gyroscope scale factors");
      v("accelerometer_misalignment", accelerometer_misalignment, "accelerometer axis misalignment");
      v("gyroscope_misalignment", gyroscope_misalignment, "gyroscope axis misalignment");
      v("accelerometer_saturation_mps2", accelerometer_saturation_mps2, "per-axis accelerometer range");
      v("gyroscope_saturation_radps", gyroscope_saturation_radps, "per-axis gyroscope range");
      v("timeshift_cam_imu_s", timeshift_cam_imu_s, "t_imu = t_cam + shift, s");
    }
    void validate() const;
  };

  /// `trajectory` must outlive the simulator. `seed` seeds the four noise streams.
  ImuSimulator(const ContinuousTrajectory& trajectory, const Options& options, std::uint64_t seed);

  /// Next sample; false once the true time would pass the trajectory's end.
  bool next(ImuMeasurement& out);

  /// Number of samples the whole stream holds.
  std::int64_t sampleCount() const { return count_; }
  /// Stamp of sample k on the IMU clock: first + round(k · 1e9 / rate) ns.
  TimeNs stampOf(std::int64_t k) const;

  const Options& options() const { return options_; }

  /// The ideal reading of a state: specific force R_W_Bᵀ(a_W − g_W) and ω_B.
  static ImuSample ideal(const TrajectoryState& state, double gravity_mps2);

 private:
  const ContinuousTrajectory& trajectory_;
  Options options_;
  RandomStream accel_noise_, gyro_noise_, accel_bias_rng_, gyro_bias_rng_;
  TimeNs shift_ns_ = 0;
  std::int64_t count_ = 0;
  std::int64_t k_ = 0;
  Vec3 accel_bias_, gyro_bias_;
  double accel_sigma_ = 0.0, gyro_sigma_ = 0.0, accel_walk_ = 0.0, gyro_walk_ = 0.0;
};

}  // namespace evio

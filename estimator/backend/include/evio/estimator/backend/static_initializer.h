#pragma once
/// @file static_initializer.h
/// Static initialisation from a still IMU (docs/algorithms.md#static-initialisation; xVIO has none):
/// over a window of readings with small spread, the mean specific force ā is
/// −g_W seen in B, so R_W_B ā/‖ā‖ = e_z fixes roll and pitch (yaw is set to
/// `yaw_rad`, it is unobservable), and the mean rate is the gyroscope bias.
/// The accelerometer bias is left at zero (inseparable from tilt when still).

#include <optional>

#include "evio/core/imu_sample.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/backend/imu_propagation.h"

namespace evio::estimator {

struct StaticInitResult {
  ImuState state;         ///< at the last reading of the window, v = 0
  Vec3 acc_std = Vec3::Zero();   ///< per-axis spread of the window, m/s²
  Vec3 gyro_std = Vec3::Zero();  ///< rad/s
};

/// Estimates the state from `samples` (at least 2, time-ordered) if the spread
/// of every axis stays within max_acc_std_mps2 and max_gyro_std_radps and the
/// mean specific force is within 20 % of gravity_mps2; std::nullopt otherwise.
std::optional<StaticInitResult> staticInitialize(const ImuSamples& samples, double gravity_mps2,
                                                 double max_acc_std_mps2, double max_gyro_std_radps,
                                                 const Vec3& p_W_B = Vec3::Zero(), double yaw_rad = 0.0);

/// What a still IMU says about the state (docs/algorithms.md#gyroscope-bias-from-tracks,
/// "At rest"): over T seconds at rest the mean rate is the gyroscope bias and
/// the mean specific force is gravity seen in the body plus the accelerometer
/// bias,
///   ω̄ = b_g + n_g,   ā = R_W_Bᵀ (0, 0, g) + b_a + n_a,
/// with n the white noise of density σ averaged over the N readings (variance
/// σ² f / N per axis at the sensor's rate f, the median spacing's inverse:
/// σ²/T without gaps) plus the bias's own random walk over the window
/// (σ_b² T / 3, the variance of its mean about its value at the start). The planet's rotation
/// (7e-5 rad/s on Earth and Mars) is not removed.
struct RestMeasurement {
  TimeNs t0_ns = 0, t1_ns = 0;  ///< the readings' span
  Vec3 mean_gyro = Vec3::Zero(), mean_acc = Vec3::Zero();
  double gyro_variance = 0.0;   ///< per axis, (rad/s)²
  double acc_variance = 0.0;    ///< per axis, (m/s²)²
  double durationS() const { return nsToSeconds(t1_ns - t0_ns); }
};

/// The readings' rate from their median spacing, Hz (a gap does not pass
/// for a slower sensor); 0 for fewer than two readings or no positive spacing.
double medianRateHz(const ImuSamples& samples);

/// The rest measurement of `samples` when staticInitialize accepts them as
/// still and they span a positive time; std::nullopt otherwise. The spread
/// bounds are what motion may add: each is combined in quadrature with the
/// white noise's spread per reading, σ √f at the readings' rate f.
std::optional<RestMeasurement> restMeasurement(const ImuSamples& samples, double gravity_mps2, double max_acc_std_mps2,
                                               double max_gyro_std_radps, const ImuNoiseDensities& noise);

/// The rest measurement as one Kalman update of the IMU state x (error state
/// and covariance P in the filter's order, filter_state.h) at the window's
/// start: H = [∂h/∂δθ = [R̂ᵀ g_up]×, ∂h/∂b_a = I] for the force (the local
/// attitude error, R = R̂ Exp(δθ), so Rᵀ g_up ≈ R̂ᵀ g_up + [R̂ᵀ g_up]× δθ) and
/// ∂h/∂b_g = I for the rate. The attitude and the accelerometer bias stay
/// correlated through it: with a loose attitude the force moves the tilt and
/// b_a together. The update is iterated (relinearised at each iterate) and
/// the force's prediction and noise carry the mean and covariance of its
/// second-order terms in the attitude error (a tilt lowers it along itself,
/// a yaw error turns the tilt's term sideways), which a loose attitude
/// makes larger than the readings' noise. Returns false (x, P untouched) if
/// S is not positive definite or the innovation fails the χ²₆ gate at 0.999
/// against the prior (a steady turn or a smooth acceleration, which the
/// spread test cannot see, taken for bias).
bool applyRestMeasurement(const RestMeasurement& rest, double gravity_mps2, ImuState* x,
                          Eigen::Matrix<double, 15, 15>* P);

}  // namespace evio::estimator

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

}  // namespace evio::estimator

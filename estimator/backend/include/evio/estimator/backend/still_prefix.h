#pragma once
/// @file still_prefix.h
/// Where a still IMU starts to move (docs/algorithms.md#gyroscope-bias-from-tracks,
/// "Still until it moves"). The readings are cut into blocks of equal count;
/// block k's mean m_k (gyroscope and accelerometer, per axis) is compared
/// with the mean of the blocks before it, m̄_k = (m_0 + … + m_{k−1}) / k. At
/// rest both are the same constant plus white noise of variance σ_b² = σ² f / n
/// per block (density σ, rate f, n readings per block), so their difference
/// has variance σ_b² (1 + 1/k); the prefix ends before the first block whose
/// difference exceeds c σ_b √(1 + 1/k) on any axis (c = threshold_sigma).
///
/// A drift the test lets through moves the prefix's mean by less than about
/// c σ_b; the prefix's rest measurement carries it as a uniform error on
/// ±c σ_b, variance (c σ_b)² / 3 per axis (StillPrefix::*_allowance_variance).
/// What no test of the IMU alone can see is a turn at a steady rate or a
/// steady acceleration from the first reading on: its mean is taken for
/// bias. applyRestMeasurement's χ² gate against the prior is the guard there.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "evio/core/imu_sample.h"
#include "evio/estimator/backend/imu_propagation.h"

namespace evio::estimator {

struct StillPrefixTest {
  double block_s = 0.05;         ///< block length, s (rounded to whole readings)
  double threshold_sigma = 4.0;  ///< c: the change a block's mean may show, in σ of the difference
  double min_s = 0.1;            ///< shortest prefix worth a rest measurement, s
};

struct StillPrefix {
  std::size_t readings = 0;             ///< the prefix: samples[0, readings)
  bool every_block = false;             ///< no block moved (the readings after the last whole block untested)
  double gyro_allowance_variance = 0;   ///< (c σ_b)² / 3 of the gyroscope, (rad/s)² per axis
  double acc_allowance_variance = 0;    ///< of the accelerometer, (m/s²)² per axis
};

/// The still prefix of `samples` (time-ordered), std::nullopt when it spans
/// less than test.min_s (or the readings do not make two blocks).
std::optional<StillPrefix> stillPrefix(const ImuSamples& samples, const ImuNoiseDensities& noise,
                                       const StillPrefixTest& test);

/// One feature's unit bearing in the camera at one time.
struct BearingObservation {
  TimeNs t_ns = 0;
  std::int64_t id = 0;
  Vec3 bearing = Vec3::UnitZ();
};

/// What the images say about the same interval: the camera's mean rotation
/// rate ω (camera frame) from each feature's first and last bearing in it.
/// A static point seen from a camera turning at ω moves as
///   b(t_b) ≈ b(t_a) + [b(t_a)]× ω (t_b − t_a),
/// one linear least-squares problem in ω over the features (at least
/// min_features, each seen min_span_s apart), with each bearing's noise σ
/// given (rad per axis): covariance 2 σ² A⁻¹, A = Σ Δt² [b]×ᵀ [b]×. The
/// noise is stated, not taken from the residuals: a still camera's tracks
/// barely move, and tracks that jump about must count against rest, not
/// inflate the noise until anything passes. Translation moves the bearings
/// too; at rest there is none, so anything that moves them speaks against
/// rest.
struct ImageRotationRate {
  Vec3 omega_C = Vec3::Zero();     ///< rad/s
  Mat3 covariance = Mat3::Zero();  ///< (rad/s)²
  int features = 0;
  /// ωᵀ C⁻¹ ω: χ²₃ when the camera is still.
  double chi2() const;
};

std::optional<ImageRotationRate> imageRotationRate(const std::vector<BearingObservation>& observations,
                                                   TimeNs t0_ns, TimeNs t1_ns, double sigma_bearing_rad,
                                                   int min_features = 5, double min_span_s = 0.02);

}  // namespace evio::estimator

#pragma once
/// @file gyro_predictor.h
/// IMU-based prediction of feature positions between EKLT batches
/// (Mahlknecht et al. 2022, Speedup Strategies, after Bloesch et al. 2015): the
/// camera rotation between two times, integrated from the gyro, moves a
/// feature as if it were infinitely far away:
///   R_B0_B1 = Π Exp(ω_k Δt_k)         (ω linearly interpolated, midpoint rule)
///   R_C0_C1 = R_C_B R_B0_B1 R_B_C,    f1 = R_C0_C1ᵀ f0,   uv1 = π(f1)
/// with f0 the bearing of uv0 (camera model, distortion included). Gyro bias
/// is not estimated here; translation is ignored.

#include <deque>
#include <optional>

#include "evio/core/camera/camera.h"
#include "evio/core/imu_sample.h"
#include "evio/core/pose.h"

namespace evio::estimator {

class GyroPredictor {
 public:
  /// `T_B_C`: camera frame C into body (IMU) frame B. Samples older than
  /// `history_s` before the newest are dropped, so memory stays flat.
  GyroPredictor(Camera camera, const Pose& T_B_C, double history_s = 2.0);

  /// Adds a sample; times must increase.
  void addImu(const ImuSample& sample);

  /// R_B0_B1: the body orientation at t1 relative to t0 (identity when
  /// t1 == t0; the inverse when t1 < t0). Outside the covered interval the
  /// nearest gyro value is held. Identity when no sample has arrived.
  Mat3 rotation(TimeNs t0_ns, TimeNs t1_ns) const;

  /// Position at t1 of the feature seen at uv0 at t0; nullopt when it cannot
  /// be unprojected or projects behind the camera.
  std::optional<Vec2> predict(const Vec2& uv0, TimeNs t0_ns, TimeNs t1_ns) const;

  bool empty() const { return samples_.empty(); }

 private:
  Vec3 gyroAt(TimeNs t_ns) const;
  Mat3 integrate(TimeNs t0_ns, TimeNs t1_ns) const;  // t0 <= t1
  Camera camera_;
  Mat3 R_B_C_;
  TimeNs history_ns_;
  std::deque<ImuSample> samples_;
};

}  // namespace evio::estimator

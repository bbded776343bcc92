#pragma once
/// @file measurements.h
/// The measurement contract of the estimator: the plain data that flows
/// between its stages (docs/architecture.md#the-estimator-stages).
///
///   frontend ──TrackPoint──► synchroniser ──MeasurementSet──► backend ──Estimate──► writer
///                                                  ImuSample ─┘
///
/// The frontend (trackers) and the backend (the EKF) both include this header
/// and neither owns it: it holds types only, no logic, so that the backend
/// builds and is tested without any frontend, and a new tracker only has to
/// produce TrackPoints. Pixel positions are distorted image coordinates of the
/// tracker's camera (core/camera/camera_common.h); times are nanoseconds on
/// the camera clock unless a field says otherwise.

#include <cstdint>
#include <utility>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/imu_sample.h"
#include "evio/core/pose.h"
#include "evio/core/time.h"

namespace evio::estimator {

/// Identifier of a feature track, unique within one tracker run (never reused).
using FeatureId = std::int64_t;

// ---------------------------------------------------------------------------------
// Frontend → synchroniser

/// Where a track point stands in the life of its track.
enum class TrackStatus : std::uint8_t {
  kNew,      ///< first point of a new track
  kTracked,  ///< a further point of a live track
  kLost,     ///< the track ended; uv/t_ns repeat its last good point
};

/// One sample of a feature track.
struct TrackPoint {
  FeatureId feature_id = 0;
  TimeNs t_ns = 0;                ///< time of the sample (EKLT: middle of the event batch)
  Vec2 uv = Vec2::Zero();         ///< position in px, distorted image coordinates
  double quality = 1.0;           ///< tracking quality in [0, 1] (EKLT: 1 − cost/2; KLT: 1)
  TrackStatus status = TrackStatus::kTracked;
  /// Covariance of uv, px² (distorted image axes), as the tracker states it
  /// (EKLT: from the curvature of its cost, eklt_cost.h). Zero: not stated,
  /// the backend uses its configured σ_img.
  Mat2 cov_px = Mat2::Zero();
  /// Time constant of the tracker's error on this track, s, as the tracker
  /// states it (its option error_time_s): the error of points Δt apart is
  /// correlated as e^(−Δt/τ). 0: independent from point to point.
  double error_time_s = 0.0;
  /// An event tracker measured this point on a sensor frame, at the frame's
  /// time, not from events (EKLT's detection and its bootstrap on the next
  /// frame; not on images rebuilt from events, which lag as the events do):
  /// it carries none of the event tracker's lag, so the synchroniser does
  /// not compensate one. KLT, which tracks on frames alone, leaves it false:
  /// its compensation (sync.track_latency_s, track_lag_px) is off unless set.
  bool measured_on_frame = false;
};

using TrackPoints = std::vector<TrackPoint>;

// ---------------------------------------------------------------------------------
// Synchroniser → backend

/// One feature in a measurement set.
struct FeatureMeasurement {
  FeatureId id = 0;
  Vec2 uv = Vec2::Zero();           ///< at the set's time, px (distorted image)
  Vec2 uv_previous = Vec2::Zero();  ///< as sent at the previous update (= uv when none)
  bool has_previous = false;        ///< false for a track new since the previous update
  /// Covariance of uv, px²; zero: not stated (the backend's σ_img). The
  /// covariance of the track point uv comes from (not grown by extrapolation).
  Mat2 cov_px = Mat2::Zero();
  /// The time constant of the tracker's error stated with that point
  /// (TrackPoint::error_time_s); the backend weighs a SLAM feature's
  /// observations by it (docs/algorithms.md#correlated-measurements).
  double error_time_s = 0.0;
  /// False when uv repeats what an earlier update already told (no new track
  /// point, or less motion than the synchroniser's min_displacement_px since
  /// the last informative position): the backend keeps the feature alive
  /// but takes no observation of it (docs/algorithms.md#correlated-measurements).
  bool informative = true;
};

/// The positions of the live features at one time: one backend update.
struct MeasurementSet {
  TimeNs t_ns = 0;
  std::vector<FeatureMeasurement> features;
};

/// A laser range-finder reading along the camera's optical axis.
struct RangeMeasurement {
  TimeNs t_ns = 0;      ///< camera clock
  double range_m = 0.0;
};

/// Where corners of the first frame are found in one later frame (or the
/// first itself), by the frontend's still probe (still_frame_probe.h): the
/// images' evidence of rest for the backend's first window, never an update.
struct FrameCorners {
  TimeNs t_ns = 0;                                    ///< camera clock
  std::vector<std::pair<FeatureId, Vec2>> corners_px;  ///< corner index, position
};

// IMU readings: evio::ImuSample (core/imu_sample.h), IMU clock, body frame B.

// ---------------------------------------------------------------------------------
// Backend → writer

/// Mean of the IMU (body) state at time t_ns.
struct ImuState {
  TimeNs t_ns = 0;                  ///< IMU clock
  Vec3 p_W_B = Vec3::Zero();        ///< position of B in W, m
  Vec3 v_W = Vec3::Zero();          ///< velocity of B in W, m/s
  Quat q_W_B = Quat::Identity();    ///< attitude of B in W
  Vec3 b_g = Vec3::Zero();          ///< gyroscope bias, rad/s (reading = ω + b_g + noise)
  Vec3 b_a = Vec3::Zero();          ///< accelerometer bias, m/s² (reading = a + b_a + noise)

  Pose T_W_B() const { return Pose(q_W_B, p_W_B); }
};

/// The innovations of one visual update, for self-diagnosis: every gated
/// feature's normalised innovation squared rᵀ S⁻¹ r (S = H P Hᵀ + R, R the
/// measurement covariance: per observation, or σ² I),
/// summed with its degrees of freedom, whether the gate accepted it or not.
/// For a consistent filter E[nis] = dof.
struct InnovationStats {
  double nis = 0.0;       ///< Σ rᵀ S⁻¹ r over the gated features
  int dof = 0;            ///< Σ residual dimensions
  int accepted = 0;       ///< features the gates let into the update
  int rejected = 0;       ///< features the gates turned away
  double nis_accepted = 0.0;  ///< the part of nis from the accepted features
  int dof_accepted = 0;       ///< the part of dof from the accepted features
};

/// The filter's estimate at one time, with the covariances the writer reports.
struct Estimate {
  TimeNs t_ns = 0;   ///< IMU clock
  ImuState imu;      ///< p_W_B, v_W, q_W_B, b_g, b_a
  Pose T_W_B;        ///< body (IMU) pose
  Pose T_W_C;        ///< camera pose T_W_B · T_B_C
  /// Covariance of [δp_W_B; δθ_B] (position first; R_W_B = R̂ Exp(δθ_B), δθ in B), m², rad².
  Mat6 cov_pose_B = Mat6::Zero();
  /// Covariance of [δp_W_C; δθ_C] of the camera pose, same convention (δθ in C).
  Mat6 cov_pose_C = Mat6::Zero();
  /// IMU block [δp δv δθ δb_g δb_a] of the error-state covariance.
  Eigen::Matrix<double, 15, 15> cov_imu = Eigen::Matrix<double, 15, 15>::Zero();
  int num_clones = 0;
  int num_slam_features = 0;
  int num_msckf_features = 0;  ///< MSCKF features used in this update
  InnovationStats innovation;  ///< of the visual update that produced this estimate
};

}  // namespace evio::estimator

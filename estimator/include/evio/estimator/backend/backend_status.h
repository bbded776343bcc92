#pragma once
/// @file backend_status.h
/// What the backend reports: its status (divergence and failure are a status,
/// never an abort), the estimate after each update, and counters.

#include <cstdint>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/core/time.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

struct BackendStatus {
  enum class Code { kOk, kDiverged, kFailed };
  Code code = Code::kOk;
  TimeNs t_ns = 0;    ///< time of the divergence or failure (IMU clock)
  std::string cause;  ///< one line, e.g. "covariance not positive definite"

  bool ok() const { return code == Code::kOk; }
};

/// "ok", "diverged" or "failed".
const char* statusName(BackendStatus::Code code);

/// The estimate at one filter time.
struct BackendEstimate {
  TimeNs t_ns = 0;   ///< IMU clock
  ImuState imu;      ///< p_W_B, v_W, q_W_B, b_g, b_a
  Pose T_W_B;        ///< body (IMU) pose
  Pose T_W_C;        ///< camera pose T_W_B · T_B_C
  /// Covariance of [δp_W_B; δθ_B] (position first; R_W_B = R̂ Exp(δθ_B), δθ in B), m², rad².
  Mat6 cov_pose_B = Mat6::Zero();
  /// Covariance of [δp_W_C; δθ_C] of the camera pose, same convention (δθ in C).
  Mat6 cov_pose_C = Mat6::Zero();
  Eigen::Matrix<double, 15, 15> cov_imu = Eigen::Matrix<double, 15, 15>::Zero();  ///< IMU block (filter_state.h order)
  int num_clones = 0;
  int num_slam_features = 0;
  int num_msckf_features = 0;  ///< MSCKF features used in this update
};

/// Counters of one run.
struct BackendStats {
  std::int64_t imu_samples = 0;
  std::int64_t imu_outliers_replaced = 0;
  std::int64_t imu_duplicates_dropped = 0;
  std::int64_t imu_gaps = 0;
  std::int64_t measurement_sets = 0;          ///< processed
  std::int64_t measurements_late_dropped = 0;
  std::int64_t measurements_before_init = 0;
  std::int64_t features_undistort_failed = 0;
  std::int64_t msckf_features_used = 0;
  std::int64_t msckf_features_rejected = 0;   ///< χ² gate
  std::int64_t msckf_features_no_parallax = 0;
  std::int64_t msckf_triangulation_failed = 0;
  std::int64_t slam_initialized_triangulated = 0;
  std::int64_t slam_initialized_prior = 0;
  std::int64_t slam_initialized_range = 0;    ///< depth prior from the range finder
  std::int64_t slam_updates_rejected = 0;     ///< Mahalanobis gate
  std::int64_t slam_features_removed = 0;     ///< lost, gated out or invalid
  std::int64_t slam_reanchored = 0;
  std::int64_t range_updates = 0;
  std::int64_t range_rejected = 0;
  std::int64_t zero_velocity_updates = 0;
};

}  // namespace evio::estimator

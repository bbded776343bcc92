#pragma once
/// @file backend_status.h
/// What the backend reports: its status (divergence and failure are a status,
/// never an abort), the estimate after each update, and counters.

#include <cstdint>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/time.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

/// The backend's status. Its code is the estimate's status code
/// (core/io/status_yaml.h): one enum from the filter to status.yaml.
struct BackendStatus {
  using Code = io::EstimateStatus::Code;
  Code code = Code::kOk;
  TimeNs t_ns = 0;    ///< time of the divergence or failure (IMU clock)
  std::string cause;  ///< one line, e.g. "covariance not positive definite"

  bool ok() const { return code == Code::kOk; }
};

/// Counters of one run (summary.yaml `backend`, written through fields()).
struct BackendStats {
  std::int64_t imu_samples = 0;
  std::int64_t imu_outliers_replaced = 0;
  std::int64_t imu_duplicates_dropped = 0;
  std::int64_t imu_gaps = 0;
  std::int64_t measurement_sets = 0;  ///< processed
  std::int64_t measurements_late_dropped = 0;
  std::int64_t measurements_before_init = 0;
  std::int64_t features_undistort_failed = 0;
  std::int64_t msckf_features_used = 0;
  std::int64_t msckf_features_rejected = 0;  ///< χ² gate
  std::int64_t msckf_features_no_parallax = 0;
  std::int64_t msckf_triangulation_failed = 0;
  std::int64_t msckf_rotation_used = 0;      ///< of msckf_features_used: rotation rows (msckf_rotation_rows)
  std::int64_t msckf_rotation_rejected = 0;  ///< rotation rows rejected by the χ² gate
  std::int64_t slam_initialized_triangulated = 0;
  std::int64_t slam_initialized_prior = 0;
  std::int64_t slam_initialized_range = 0;  ///< depth prior from the range finder
  std::int64_t slam_initialized_prior_track = 0;  ///< a depth prior with the track's observations (slam_prior_init_with_track)
  std::int64_t slam_initialized_map = 0;    ///< depth prior from the map's median depth
  std::int64_t slam_scene_depth_measured = 0;  ///< updates of the scene depth from the triangulated points (0 or 1)
  std::int64_t slam_waiting_for_depth = 0;  ///< waits of SLAM candidates for a depth, per set (slam_fixed_prior_wait_s)
  std::int64_t slam_updates_rejected = 0;  ///< Mahalanobis gate
  std::int64_t slam_features_removed = 0;  ///< lost, gated out or invalid
  std::int64_t slam_reanchored = 0;
  std::int64_t range_updates = 0;
  std::int64_t range_rejected = 0;
  std::int64_t zero_velocity_updates = 0;

  template <class V>
  void fields(V& v) {
    v("imu_samples", imu_samples, "imu samples");
    v("imu_outliers_replaced", imu_outliers_replaced, "imu outliers replaced");
    v("imu_duplicates_dropped", imu_duplicates_dropped, "imu duplicates dropped");
    v("imu_gaps", imu_gaps, "imu gaps");
    v("measurement_sets", measurement_sets, "measurement sets processed");
    v("measurements_late_dropped", measurements_late_dropped, "measurements late dropped");
    v("measurements_before_init", measurements_before_init, "measurements before init");
    v("features_undistort_failed", features_undistort_failed, "features undistort failed");
    v("msckf_features_used", msckf_features_used, "msckf features used");
    v("msckf_features_rejected", msckf_features_rejected, "MSCKF features rejected by the chi-squared gate");
    v("msckf_features_no_parallax", msckf_features_no_parallax, "msckf features no parallax");
    v("msckf_triangulation_failed", msckf_triangulation_failed, "msckf triangulation failed");
    v("msckf_rotation_used", msckf_rotation_used, "of the MSCKF features used, tracks without parallax used as rotation rows");
    v("msckf_rotation_rejected", msckf_rotation_rejected, "rotation rows rejected by the chi-squared gate");
    v("slam_initialized_triangulated", slam_initialized_triangulated, "slam initialized triangulated");
    v("slam_initialized_prior", slam_initialized_prior, "slam initialized prior");
    v("slam_initialized_range", slam_initialized_range, "SLAM features initialised with a range-finder depth prior");
    v("slam_initialized_prior_track", slam_initialized_prior_track,
      "SLAM features initialised from a depth prior and the track's observations together");
    v("slam_initialized_map", slam_initialized_map, "SLAM features initialised with the map's depth prior");
    v("slam_scene_depth_measured", slam_scene_depth_measured,
      "updates of the scene inverse depth from the triangulated points' median (0 or 1)");
    v("slam_waiting_for_depth", slam_waiting_for_depth, "SLAM candidates left waiting for a depth, counted once per measurement set");
    v("slam_updates_rejected", slam_updates_rejected, "SLAM observations rejected by the Mahalanobis gate");
    v("slam_features_removed", slam_features_removed, "SLAM features removed: lost, gated out or invalid");
    v("slam_reanchored", slam_reanchored, "slam reanchored");
    v("range_updates", range_updates, "range updates");
    v("range_rejected", range_rejected, "range rejected");
    v("zero_velocity_updates", zero_velocity_updates, "zero velocity updates");
  }
};

}  // namespace evio::estimator

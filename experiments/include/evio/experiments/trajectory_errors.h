#pragma once
/// @file trajectory_errors.h
/// Absolute errors of an aligned estimate (docs/evaluation.md#paper-metrics
/// and docs/evaluation.md#absolute-trajectory-error): per-pose errors, their
/// statistics (ATE), the EKLT-VIO paper's distance-normalised mean errors and
/// per-minute drift.
///
/// Per associated pose k, with the aligned estimate (p̂_k, R̂_k) and the
/// interpolated ground truth (p_k, R_k), both in W:
///   position error  e_p,k = ‖p_k − p̂_k‖                         (m)
///   rotation error  e_R,k = angle(R̂_kᵀ R_k) = ‖Log(R̂_k R_kᵀ)‖    (deg)
///   yaw error       e_ψ,k = yaw(R̂_k R_kᵀ), z-y-x Euler, in (−180, 180] (deg)
///   gravity error   e_g,k = angle between R̂_k R_kᵀ e_z and e_z (roll–pitch, deg)
/// The rotation error R̂ R_gtᵀ is taken in W (the RPG trajectory evaluation
/// toolbox's convention), so its yaw is a rotation about gravity.

#include <vector>

#include "evio/core/pose.h"
#include "evio/experiments/trajectory_alignment.h"
#include "evio/experiments/trajectory_association.h"

namespace evio::experiments {

/// The errors of one associated pose after alignment.
struct PoseError {
  TimeNs t_ns = 0;             ///< estimate time
  double distance_m = 0.0;     ///< ground-truth path length from the first associated pose, m
  Vec3 p_gt = Vec3::Zero();    ///< ground-truth position in W, m
  Vec3 p_es = Vec3::Zero();    ///< aligned estimated position in W, m
  double position_m = 0.0;
  double rotation_deg = 0.0;
  double yaw_deg = 0.0;        ///< signed
  double gravity_deg = 0.0;
};

/// Statistics of a set of non-negative errors.
struct ErrorStats {
  std::size_t count = 0;
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double max = 0.0;
};

/// RMSE, mean, median (mean of the middle two for an even count) and max;
/// all zero for an empty set.
ErrorStats errorStats(std::vector<double> values);

/// Applies `alignment` to each associated estimate and computes its errors.
std::vector<PoseError> poseErrors(const Association& association, const Alignment& alignment);

/// The EKLT-VIO paper's metrics plus the absolute errors they normalise.
struct PaperMetrics {
  double groundtruth_length_m = 0.0;  ///< L_gt: path length of the whole ground truth
  double mpe_percent = 0.0;           ///< 100 · mean_k e_p,k / L_gt
  double mre_deg_per_m = 0.0;         ///< mean_k e_R,k / L_gt
  double mye_deg_per_m = 0.0;         ///< mean_k |e_ψ,k| / L_gt
  double mean_position_m = 0.0;       ///< mean_k e_p,k
  double mean_rotation_deg = 0.0;     ///< mean_k e_R,k
  double mean_yaw_deg = 0.0;          ///< mean_k |e_ψ,k|
};

/// Paper metrics of `errors` for a ground truth of length L_gt (> 0; the
/// normalised figures are NaN when L_gt is 0).
PaperMetrics paperMetrics(const std::vector<PoseError>& errors, double groundtruth_length_m);

/// Absolute trajectory error: statistics of e_p (m) and e_R (deg).
struct AteMetrics {
  ErrorStats position_m;
  ErrorStats rotation_deg;
};
AteMetrics absoluteTrajectoryError(const std::vector<PoseError>& errors);

/// Drift per minute for hover and rotation-only runs, where the % figures
/// explode: the mean error over the last `window_s` of the run divided by
/// the run's length (first to last associated pose) in minutes.
struct DriftMetrics {
  double final_position_m = 0.0;
  double final_rotation_deg = 0.0;
  double position_m_per_min = 0.0;
  double rotation_deg_per_min = 0.0;
};
DriftMetrics driftMetrics(const std::vector<PoseError>& errors, double window_s);

}  // namespace evio::experiments

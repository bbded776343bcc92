#pragma once
/// @file metrics_format.h
/// Metrics of `evio evaluate` as a human table, JSON (metrics.json) and CSV.
///
/// metrics.json ("format": "evio-metrics/1"), keys in this order:
///   format, inputs{estimate, groundtruth, covariance, timing, status}  (paths or null)
///   status (ok|diverged|failed), cause, estimator_status (ok|degraded|diverged|failed|unknown)
///   association{estimate_poses, groundtruth_poses, matched_poses, matched_share,
///               max_time_difference_s, time_offset_s}
///   groundtruth{duration_s, length_m}
///   alignment{describe, type, window, first_n, start_s, end_s, poses_used,
///             window_start_s, window_end_s, rotation_from_orientation, scale,
///             rotation[9] (row-major), translation[3]}
///   paper{alignment, mpe_percent, mre_deg_per_m, mye_deg_per_m, mean_position_m,
///         mean_rotation_deg, mean_yaw_deg}
///   ate{alignment, position_m{count, rmse, mean, median, max}, rotation_deg{...}}
///   drift{alignment, final_position_m, final_rotation_deg, position_m_per_min, rotation_deg_per_min}
///   rpe{alignment, <label>{length_m, translation_percent{...}, yaw_deg{...}, yaw_deg_per_m,
///       gravity_deg{...}}...}                              labels "10pct", "5m", …
///   nees{available, alignment, rotation_error, poses, singular, mean_pose, mean_position,
///        mean_orientation, share_in_bounds, bounds_pose_95[2]}
///   rtf{available, grid_s, intervals, median, max, overall, mean_event_rate_hz,
///       median_features, median_per_feature}   (the last two when timing.txt has features)
///   divergence{alignment, diverged, time_s, cause, max_ratio, fraction_of_distance, offset_m}
///   completion{alignment, share, max_gap_s}
/// Every group whose numbers depend on the alignment carries the alignment's
/// description ("posyaw on t0+3..8 s (1001 poses)"). Non-finite numbers are null.
///
/// The per-pose series (metrics_poses.csv):
///   t_s,distance_m,gt_x,gt_y,gt_z,es_x,es_y,es_z,position_m,rotation_deg,yaw_deg,
///   gravity_deg,nees_position,nees_orientation,nees_pose      (NEES empty where absent)
/// and the RTF series (metrics_rtf.csv): t_s,rtf,event_rate_hz, then
/// features,rtf_per_feature when timing.txt has the features column
/// (real_time_factor.h; rtf_per_feature empty where no feature was tracked).

#include <string>

#include "evio/experiments/json_value.h"
#include "evio/experiments/trajectory_metrics.h"

namespace evio::experiments {

/// Paths of the files that were scored (empty: not used).
struct MetricsSources {
  std::string estimate;
  std::string groundtruth;
  std::string covariance;
  std::string timing;
  std::string status;
};

/// The metrics.json tree.
JsonValue metricsJson(const Metrics& metrics, const EvaluationOptions& options, const MetricsSources& sources);

/// A human-readable table (several lines).
std::string metricsTable(const Metrics& metrics);

/// One CSV header line and one row: the flattened scalar leaves of
/// metricsJson() (dotted keys), without the input paths.
std::string metricsCsv(const JsonValue& metrics_json);

/// The per-pose series (see above).
std::string poseErrorsCsv(const Metrics& metrics);

/// The RTF series.
std::string rtfCsv(const Metrics& metrics);

/// A CSV field, quoted when it holds a comma, quote or newline.
std::string csvField(const std::string& text);

}  // namespace evio::experiments

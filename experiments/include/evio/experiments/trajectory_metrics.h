#pragma once
/// @file trajectory_metrics.h
/// `evio evaluate` as a library call: scores one estimated trajectory
/// against ground truth with every metric of docs/evaluation.md — association,
/// alignment, the paper's MPE/MRE/MYE, ATE, RPE, NEES (with covariances),
/// real-time factor (with timing.txt), completion and divergence (with
/// status.yaml) — and records the alignment each number depends on.
///
/// Run outcome (Metrics::status):
///  - "failed":   the estimator's status.yaml says failed;
///  - "diverged": status.yaml says diverged, or at some associated pose the
///                position error exceeds fraction·d_k + offset_m (d_k the
///                ground-truth distance travelled since the first associated
///                pose; default 10 % of distance plus 1 m), on aligned or
///                unaligned errors (DivergenceOptions::use_alignment);
///  - "ok":       otherwise.
/// Completion is the share of the ground truth's duration covered by
/// associated estimate poses before any divergence: the sum of the gaps
/// between consecutive such poses that are no longer than
/// completion_max_gap_s, over (last − first ground-truth time).

#include <optional>
#include <string>
#include <vector>

#include "evio/core/io/status_yaml.h"
#include "evio/core/io/timing_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/options.h"
#include "evio/experiments/nees.h"
#include "evio/experiments/real_time_factor.h"
#include "evio/experiments/relative_pose_error.h"
#include "evio/experiments/trajectory_alignment.h"
#include "evio/experiments/trajectory_association.h"
#include "evio/experiments/trajectory_errors.h"

namespace evio::experiments {

struct DivergenceOptions {
  double fraction_of_distance = 0.1;  ///< error bound: fraction · distance travelled ...
  double offset_m = 1.0;              ///< ... plus this, m
  /// Judge divergence and completion on the errors after the evaluation's
  /// alignment (true), or on the errors in the estimate's own frame (false:
  /// for runs started from the ground truth, whose frame is the truth's; an
  /// alignment window fitted to a drifting run would drag its start away
  /// and report it diverged from the first second).
  bool use_alignment = true;

  template <class V>
  void fields(V& v) {
    v("fraction_of_distance", fraction_of_distance, "error bound: this fraction of the distance travelled ...");
    v("offset_m", offset_m, "... plus this, m");
    v("use_alignment", use_alignment, "judge on aligned errors (false: in the estimate's own frame)");
  }
  void validate() const {
    requireNonNegative("fraction_of_distance", fraction_of_distance);
    requireNonNegative("offset_m", offset_m);
  }
};

/// Every option of an evaluation (a YAML map; `evio evaluate --config/--set`).
struct EvaluationOptions {
  AssociationOptions association;
  AlignmentOptions alignment;
  RpeOptions rpe;
  NeesOptions nees;
  DivergenceOptions divergence;
  double completion_max_gap_s = 1.0;  ///< longer gaps between estimate poses are not covered, s
  double drift_window_s = 1.0;        ///< final error = mean over the last this many seconds, s
  double rtf_grid_s = 0.2;            ///< RTF sampling grid of data time, s

  template <class V>
  void fields(V& v) {
    v("association", association, "matching estimate poses with ground truth");
    v("alignment", alignment, "alignment type and window");
    v("rpe", rpe, "relative pose error lengths");
    v("nees", nees, "pose NEES convention");
    v("divergence", divergence, "divergence bound");
    v("completion_max_gap_s", completion_max_gap_s, "longest gap between estimate poses counted as covered, s");
    v("drift_window_s", drift_window_s, "final error: mean over the last this many seconds, s");
    v("rtf_grid_s", rtf_grid_s, "real-time factor sampling grid, s");
  }
  void validate() const;

  /// The paper's protocol, as every shipped campaign scores it and as
  /// `evio evaluate --paper` does: the filter starts from the ground truth,
  /// so MPE/MYE/ATE/RPE use the paper's alignment (posyaw on t0+3 … t0+8 s)
  /// while NEES, divergence and completion use the errors in the estimate's
  /// own frame (the truth's). Other fields keep their defaults.
  static EvaluationOptions paper();
};

/// What is scored. Only estimate and ground truth are required.
struct EvaluationInputs {
  Trajectory estimate;
  Trajectory groundtruth;
  std::vector<io::StampedPoseCovariance> covariance;  ///< empty: no NEES
  std::optional<std::vector<io::TimingSample>> timing;  ///< absent: no RTF
  std::optional<io::EstimateStatus> status;             ///< absent: taken as ok
};

struct DivergenceResult {
  bool diverged = false;
  double time_s = 0.0;   ///< first pose over the bound, or the status time
  std::string cause;     ///< "position error 3.2 m > bound 1.9 m" or the status cause
  double max_ratio = 0.0;  ///< max_k e_p,k / bound_k (> 1: over the bound)
};

struct Metrics {
  std::string status = "ok";         ///< ok | diverged | failed
  std::string cause;                 ///< why not ok
  std::string estimator_status = "unknown";  ///< from status.yaml: ok | degraded | diverged | failed | unknown
  std::size_t estimate_poses = 0;
  std::size_t groundtruth_poses = 0;
  std::size_t matched_poses = 0;
  double matched_share = 0.0;
  double groundtruth_duration_s = 0.0;
  double groundtruth_length_m = 0.0;  ///< L_gt
  double completion = 0.0;            ///< 0..1
  Alignment alignment;                ///< recorded with every alignment-dependent number
  PaperMetrics paper;
  AteMetrics ate;
  DriftMetrics drift;
  std::vector<RpeLength> rpe;
  NeesMetrics nees;
  RtfMetrics rtf;
  DivergenceResult divergence;
  /// The ground truth's verdict alone (the error bound, not status.yaml):
  /// what the estimator's self-diagnosis is measured against.
  DivergenceResult truth_divergence;
  std::vector<PoseError> pose_errors;  ///< per associated pose (series for plots)
};

/// Scores `inputs` (options validated). Throws evio::Error when association
/// or alignment is impossible (too few matches, empty window).
Metrics evaluateTrajectory(const EvaluationInputs& inputs, const EvaluationOptions& options);

}  // namespace evio::experiments

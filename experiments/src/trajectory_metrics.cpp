#include "evio/experiments/trajectory_metrics.h"

#include <cstdio>

#include "evio/core/error.h"

namespace evio::experiments {

void EvaluationOptions::validate() const {
  const auto nested = [](const char* name, const auto& o) {
    try {
      o.validate();
    } catch (const Error& e) {
      throw Error(std::string(name) + "." + e.what());
    }
  };
  nested("association", association);
  nested("alignment", alignment);
  nested("rpe", rpe);
  nested("nees", nees);
  nested("divergence", divergence);
  requirePositive("completion_max_gap_s", completion_max_gap_s);
  requirePositive("drift_window_s", drift_window_s);
  requirePositive("rtf_grid_s", rtf_grid_s);
}

namespace {

DivergenceResult divergence(const std::vector<PoseError>& errors, const std::optional<io::EstimateStatus>& status,
                            const DivergenceOptions& options) {
  DivergenceResult d;
  for (const auto& e : errors) {
    const double bound = options.fraction_of_distance * e.distance_m + options.offset_m;
    const double ratio = bound > 0.0 ? e.position_m / bound : (e.position_m > 0.0 ? 1e300 : 0.0);
    d.max_ratio = std::max(d.max_ratio, ratio);
    if (!d.diverged && e.position_m > bound) {
      d.diverged = true;
      d.time_s = nsToSeconds(e.t_ns);
      char buf[160];
      std::snprintf(buf, sizeof(buf), "position error %.3g m > bound %.3g m (%.3g m travelled) at %.3f s",
                    e.position_m, bound, e.distance_m, d.time_s);
      d.cause = buf;
    }
  }
  if (status && status->code == io::EstimateStatus::Code::kDiverged) {
    const double t_s = status->t_ns ? nsToSeconds(*status->t_ns) : 0.0;
    if (!d.diverged || t_s < d.time_s) {
      d.time_s = t_s;
      d.cause = "estimator reports divergence" + (status->cause.empty() ? "" : ": " + status->cause);
    }
    d.diverged = true;
  }
  return d;
}

double completion(const std::vector<PoseError>& errors, const Trajectory& gt, const DivergenceResult& div,
                  const std::optional<io::EstimateStatus>& status, double max_gap_s) {
  const double duration_s = nsToSeconds(gt.back().t_ns - gt.front().t_ns);
  if (duration_s <= 0.0 || errors.empty()) return 0.0;
  double end_s = 1e300;
  if (div.diverged) end_s = div.time_s;
  if (status && status->code == io::EstimateStatus::Code::kFailed && status->t_ns)
    end_s = std::min(end_s, nsToSeconds(*status->t_ns));
  double covered = 0.0;
  const TimeNs max_gap_ns = secondsToNs(max_gap_s);
  for (std::size_t k = 1; k < errors.size(); ++k) {
    if (nsToSeconds(errors[k].t_ns) > end_s) break;
    const TimeNs gap = errors[k].t_ns - errors[k - 1].t_ns;
    if (gap <= max_gap_ns) covered += nsToSeconds(gap);
  }
  return std::min(1.0, covered / duration_s);
}

}  // namespace

EvaluationOptions EvaluationOptions::paper() {
  EvaluationOptions o;
  o.alignment = AlignmentOptions::paper();
  o.nees.use_alignment = false;
  o.divergence.use_alignment = false;
  return o;
}

Metrics evaluateTrajectory(const EvaluationInputs& in, const EvaluationOptions& options) {
  options.validate();
  require(!in.groundtruth.empty(), "evaluate: the ground truth has no poses");
  Metrics m;
  m.estimate_poses = in.estimate.size();
  m.groundtruth_poses = in.groundtruth.size();
  m.groundtruth_duration_s = nsToSeconds(in.groundtruth.back().t_ns - in.groundtruth.front().t_ns);
  m.groundtruth_length_m = pathLength(in.groundtruth);
  if (in.status) m.estimator_status = std::string(io::estimateStatusName(in.status->code));

  const Association association = associate(in.estimate, in.groundtruth, options.association);
  m.matched_poses = association.poses.size();
  m.matched_share = association.matched_share;
  m.alignment = align(association, in.groundtruth.front().t_ns, options.alignment);
  m.pose_errors = poseErrors(association, m.alignment);
  m.paper = paperMetrics(m.pose_errors, m.groundtruth_length_m);
  m.ate = absoluteTrajectoryError(m.pose_errors);
  m.drift = driftMetrics(m.pose_errors, options.drift_window_s);
  m.rpe = relativePoseError(association, m.alignment, m.groundtruth_length_m, options.rpe);
  m.nees = poseNees(association, m.alignment, in.covariance, options.nees);
  if (in.timing) m.rtf = realTimeFactor(*in.timing, options.rtf_grid_s);
  // Divergence and completion: on the aligned errors, or in the estimate's own frame.
  const std::vector<PoseError> unaligned =
      options.divergence.use_alignment ? std::vector<PoseError>{} : poseErrors(association, Alignment{});
  const std::vector<PoseError>& judged = options.divergence.use_alignment ? m.pose_errors : unaligned;
  m.divergence = divergence(judged, in.status, options.divergence);
  m.truth_divergence = divergence(judged, std::nullopt, options.divergence);
  m.completion = completion(judged, in.groundtruth, m.divergence, in.status, options.completion_max_gap_s);

  if (in.status && in.status->code == io::EstimateStatus::Code::kFailed) {
    m.status = "failed";
    m.cause = "estimator reports failure" + (in.status->cause.empty() ? "" : ": " + in.status->cause);
  } else if (m.divergence.diverged) {
    m.status = "diverged";
    m.cause = m.divergence.cause;
  }
  return m;
}

}  // namespace evio::experiments

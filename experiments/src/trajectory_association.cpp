#include "evio/experiments/trajectory_association.h"

#include <algorithm>
#include <cstdio>

#include "evio/core/error.h"

namespace evio::experiments {

void AssociationOptions::validate() const {
  requireNonNegative("max_time_difference_s", max_time_difference_s);
  requireField(std::isfinite(time_offset_s), "time_offset_s", "must be finite");
  requireInRange("min_matched_share", min_matched_share, 0.0, 1.0);
}

bool interpolatePose(const Trajectory& gt, TimeNs t_ns, TimeNs max_difference_ns, Pose* pose) {
  require(!gt.empty(), "interpolatePose: empty ground truth");
  const auto after = firstPoseAtOrAfter(gt, t_ns);
  if (after == gt.end()) {  // after the last sample
    if (t_ns - gt.back().t_ns > max_difference_ns) return false;
    *pose = gt.back().pose;
    return true;
  }
  if (after->t_ns == t_ns || after == gt.begin()) {
    if (after->t_ns - t_ns > max_difference_ns) return false;
    *pose = after->pose;
    return true;
  }
  const StampedPose& a = *(after - 1);
  const StampedPose& b = *after;
  if (std::min(t_ns - a.t_ns, b.t_ns - t_ns) > max_difference_ns) return false;
  *pose = evio::interpolatePose(a, b, t_ns);
  return true;
}

Association associate(const Trajectory& estimate, const Trajectory& groundtruth, const AssociationOptions& options) {
  options.validate();
  require(!groundtruth.empty(), "association: the ground truth has no poses");
  require(!estimate.empty(), "association: the estimate has no poses");
  const TimeNs offset_ns = secondsToNs(options.time_offset_s);
  const TimeNs max_ns = secondsToNs(options.max_time_difference_s);
  Association out;
  out.estimate_poses = estimate.size();
  out.poses.reserve(estimate.size());
  for (std::size_t i = 0; i < estimate.size(); ++i) {
    AssociatedPose a;
    a.t_ns = estimate[i].t_ns;
    a.T_W_es = estimate[i].pose;
    a.estimate_index = i;
    if (interpolatePose(groundtruth, a.t_ns + offset_ns, max_ns, &a.T_W_gt)) out.poses.push_back(a);
  }
  out.matched_share = static_cast<double>(out.poses.size()) / static_cast<double>(estimate.size());
  if (out.poses.empty() || out.matched_share < options.min_matched_share) {
    char buf[320];
    std::snprintf(buf, sizeof(buf),
                  "association: only %zu of %zu estimate poses (%.1f %%) lie within %.3f s of ground truth; "
                  "need %.1f %% (estimate spans %.3f..%.3f s, ground truth %.3f..%.3f s, offset %.3f s)",
                  out.poses.size(), estimate.size(), 100.0 * out.matched_share, options.max_time_difference_s,
                  100.0 * options.min_matched_share, nsToSeconds(estimate.front().t_ns),
                  nsToSeconds(estimate.back().t_ns), nsToSeconds(groundtruth.front().t_ns),
                  nsToSeconds(groundtruth.back().t_ns), options.time_offset_s);
    throw Error(buf);
  }
  return out;
}

double pathLength(const Trajectory& trajectory) {
  double length = 0.0;
  for (std::size_t i = 1; i < trajectory.size(); ++i)
    length += (trajectory[i].pose.translation() - trajectory[i - 1].pose.translation()).norm();
  return length;
}

}  // namespace evio::experiments

#pragma once
/// @file trajectory_association.h
/// Association of an estimated trajectory with ground truth
/// (docs/evaluation.md#association): the ground truth is interpolated at each
/// estimate's time, linearly in position and by slerp in rotation, instead of
/// taking the nearest sample. An estimate at time t (estimate clock) is compared with
/// the ground truth at t + time_offset_s; it is associated when the nearest
/// ground-truth sample lies within max_time_difference_s of that time
/// (outside the ground truth's span the end sample is used, never
/// extrapolated). Too few associations is an error, not a silent zero.
/// Both trajectories are poses T_W_X of the same frame X (the event camera in
/// the world frame, docs/architecture.md#the-sequence-folder).

#include <string>
#include <vector>

#include "evio/core/options.h"
#include "evio/core/pose.h"

namespace evio::experiments {

struct AssociationOptions {
  double max_time_difference_s = 0.02;  ///< largest distance to the nearest ground-truth sample, s
  double time_offset_s = 0.0;           ///< t_groundtruth = t_estimate + offset, s
  double min_matched_share = 0.5;       ///< fewer associated estimate poses is an error (0..1)

  template <class V>
  void fields(V& v) {
    v("max_time_difference_s", max_time_difference_s, "largest distance to the nearest ground-truth sample, s");
    v("time_offset_s", time_offset_s, "t_groundtruth = t_estimate + offset, s");
    v("min_matched_share", min_matched_share, "smallest share of estimate poses that must associate");
  }
  void validate() const;
};

/// One associated pair: the estimate and the interpolated ground truth.
struct AssociatedPose {
  TimeNs t_ns = 0;        ///< estimate time (estimate clock)
  Pose T_W_gt;            ///< ground truth interpolated at t_ns + offset
  Pose T_W_es;            ///< the estimate
  std::size_t estimate_index = 0;  ///< index in the estimate trajectory
};

struct Association {
  std::vector<AssociatedPose> poses;  ///< in estimate order (increasing time)
  std::size_t estimate_poses = 0;     ///< poses in the estimate
  double matched_share = 0.0;         ///< poses.size() / estimate_poses
};

/// Ground truth at time t by linear position and slerp rotation between the
/// bracketing samples (`groundtruth` sorted by time, not empty). Returns
/// false when the nearest sample is further than `max_difference_ns`.
bool interpolatePose(const Trajectory& groundtruth, TimeNs t_ns, TimeNs max_difference_ns, Pose* pose);

/// Associates `estimate` with `groundtruth` (both sorted by time). Throws
/// evio::Error when the ground truth is empty or fewer than
/// min_matched_share of the estimate's poses associate (the message states
/// both counts and the time spans).
Association associate(const Trajectory& estimate, const Trajectory& groundtruth, const AssociationOptions& options);

/// Length of the polyline through the positions of `trajectory`, m.
double pathLength(const Trajectory& trajectory);

}  // namespace evio::experiments

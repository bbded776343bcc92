#pragma once
/// @file relative_pose_error.h
/// Relative pose error over sub-trajectories of a given length
/// (docs/evaluation.md#relative-pose-error). With d_k the ground-truth distance
/// travelled up to associated pose k, for each start i the end j is the
/// pose whose d_j is closest to d_i + L, accepted when |d_j − d_i − L| <=
/// tolerance·L. For that pair
///   E = (T_gt,i⁻¹ T_gt,j)⁻¹ (T_es,i⁻¹ T_es,j)
/// (estimates aligned first, which matters only for sim3's scale) and
///   translation error  = 100 · ‖t_E‖ / L                  (% of L)
///   yaw error          = |yaw(R_W,i R_E R_W,iᵀ)|           (deg; also deg/m: / L)
///   gravity error      = tilt of R_W,i R_E R_W,iᵀ          (roll–pitch, deg)
/// where R_W,i = R_gt,i rotates the error from frame i into W-aligned axes
/// so that yaw is about gravity (z-y-x Euler yaw as in trajectory_errors.h).

#include <string>
#include <vector>

#include "evio/core/options.h"
#include "evio/experiments/trajectory_alignment.h"
#include "evio/experiments/trajectory_association.h"
#include "evio/experiments/trajectory_errors.h"

namespace evio::experiments {

struct RpeOptions {
  /// Sub-trajectory lengths as % of the ground-truth length L_gt.
  std::vector<double> lengths_percent = {10.0, 20.0, 30.0, 40.0, 50.0};
  std::vector<double> lengths_m = {};  ///< and/or in metres
  double tolerance = 0.2;              ///< accepted |d_j − d_i − L| / L

  template <class V>
  void fields(V& v) {
    v("lengths_percent", lengths_percent, "sub-trajectory lengths, % of the ground-truth length");
    v("lengths_m", lengths_m, "sub-trajectory lengths, m");
    v("tolerance", tolerance, "accepted relative mismatch of a pair's length");
  }
  void validate() const;
};

/// RPE for one sub-trajectory length.
struct RpeLength {
  std::string label;           ///< "10pct" or "5m" (a stable key)
  double length_m = 0.0;       ///< L
  ErrorStats translation_percent;
  ErrorStats yaw_deg;
  double yaw_deg_per_m = 0.0;  ///< yaw_deg.mean / L
  ErrorStats gravity_deg;
};

/// RPE for every requested length; lengths with no pair have count 0.
std::vector<RpeLength> relativePoseError(const Association& association, const Alignment& alignment,
                                         double groundtruth_length_m, const RpeOptions& options);

}  // namespace evio::experiments

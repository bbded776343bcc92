#pragma once
/// @file nees.h
/// Normalised estimation error squared of the pose (docs/evaluation.md#nees),
/// for estimates with covariance (the covariance TUM variant,
/// core/io/tum.h readTumCovariance: 3×3 orientation and 3×3 position blocks
/// of the estimated pose T_W_X; cross terms are not in that format and are
/// taken as zero).
///
/// The ground truth is mapped into the estimate's frame by the inverse of the
/// evaluation's alignment S (so the estimate and its covariance stay as the
/// estimator wrote them): T̃_gt = S⁻¹(T_gt) (with use_alignment; else
/// T̃_gt = T_gt). Then
///   e_p = p̃_gt − p̂                                   (m)
///   e_θ = Log(R̂ᵀ R̃_gt)   rotation_error "local":  R_true = R̂·Exp(δθ), δθ in X
///   e_θ = Log(R̃_gt R̂ᵀ)   rotation_error "global": R_true = Exp(δθ)·R̂, δθ in W
///   NEES_p = e_pᵀ P_p⁻¹ e_p (3 dof), NEES_θ = e_θᵀ P_θ⁻¹ e_θ (3 dof),
///   NEES = NEES_p + NEES_θ (6 dof, block-diagonal P).
/// "local" is the EKF backend's convention (estimator/backend/backend_status.h:
/// R_W_B = R̂ Exp(δθ_B)); the estimator writes its covariance file in it.
/// A consistent filter gives E[NEES] = 6; averaged over N runs, ANEES lies in
/// [χ²_{0.025}(6N), χ²_{0.975}(6N)] / N with 95 % probability.

#include <string>
#include <vector>

#include "evio/core/io/tum.h"
#include "evio/core/options.h"
#include "evio/experiments/trajectory_alignment.h"
#include "evio/experiments/trajectory_association.h"

namespace evio::experiments {

struct NeesOptions {
  std::string rotation_error = "local";  ///< local | global (see above)
  /// Map the ground truth by the evaluation's alignment first (true), or
  /// compare in the estimate's own frame (false: for simulation runs started
  /// at the true pose, where a window alignment only adds its own error).
  bool use_alignment = true;

  template <class V>
  void fields(V& v) {
    v("rotation_error", rotation_error, "convention of the orientation covariance: local or global");
    v("use_alignment", use_alignment, "map the ground truth by the evaluation's alignment first");
  }
  void validate() const;
};

/// NEES at one associated pose with covariance.
struct NeesSample {
  TimeNs t_ns = 0;
  double position = 0.0;     ///< 3 dof
  double orientation = 0.0;  ///< 3 dof
  double pose = 0.0;         ///< 6 dof
};

struct NeesMetrics {
  bool available = false;       ///< some associated pose had a covariance
  std::size_t poses = 0;        ///< poses with NEES
  std::size_t singular = 0;     ///< poses skipped: covariance not positive definite
  double mean_pose = 0.0;       ///< average NEES over poses (expect 6)
  double mean_position = 0.0;   ///< (expect 3)
  double mean_orientation = 0.0;  ///< (expect 3)
  /// Share of poses whose 6-dof NEES lies in [χ²_{0.025}(6), χ²_{0.975}(6)] (expect 0.95).
  double share_in_bounds = 0.0;
  std::vector<NeesSample> samples;
};

/// NEES of the associated poses whose time equals a covariance pose's time
/// (`covariance` sorted by time; poses without one are skipped).
NeesMetrics poseNees(const Association& association, const Alignment& alignment,
                     const std::vector<io::StampedPoseCovariance>& covariance, const NeesOptions& options);

/// Two-sided bounds of the average of N independent χ²(dof) values at
/// `probability` (0.95): [χ²_{(1−p)/2}(dof·N), χ²_{(1+p)/2}(dof·N)] / N.
std::pair<double, double> neesBounds(int dof, int runs, double probability = 0.95);

}  // namespace evio::experiments

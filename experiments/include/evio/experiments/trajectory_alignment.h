#pragma once
/// @file trajectory_alignment.h
/// Alignment of an estimate to ground truth (docs/evaluation.md#alignment).
/// The alignment is a similarity S = (s, R, t) applied to the estimate:
///   p_aligned = s·R·p̂ + t,   R_aligned = R·R̂,
/// found by least squares over the poses of a window, then applied to the
/// whole estimate:
///   - posyaw: s = 1, R = Rz(θ) (yaw about gravity, W's z axis) and t.
///     With centred positions x_k (estimate) and y_k (ground truth) and
///     C = Σ x_k y_kᵀ, Σ‖y_k − Rz x_k‖² is least for the θ maximising
///     trace(Rz(θ)·C) = cosθ (C00 + C11) + sinθ (C01 − C10) + C22, i.e.
///     θ = atan2(C01 − C10, C00 + C11).
///   - se3: s = 1 and R by Umeyama (1991): with the SVD U·D·Vᵀ of Cᵀ (the
///     ground-truth-by-estimate cross-covariance) and S = diag(1, 1, ±1)
///     making det(U·S·Vᵀ) = +1, R = U·S·Vᵀ.
///   - sim3: as se3 and s = trace(D·S) / Σ‖x_k‖².
///   - none: the identity.
/// In every case t = ȳ − s·R·x̄ (the means of the window's positions).
/// When the window's positions do not determine the rotation (the estimate's
/// or the truth's: posyaw: an RMS horizontal spread below min_spread_m, e.g.
/// a hover, or an estimate drifting over a still truth; se3: positions that
/// do not span a plane, second RMS singular value below min_spread_m),
/// the rotation is taken from the orientations instead: M = Σ R̂_k R_gt,kᵀ
/// replaces C (the same trace maximisation, as R·R̂_k ≈ R_gt,k), and the
/// result says so (rotation_from_orientation). sim3 then is an error.
///
/// Window: all poses, the first N associated poses, or the poses with
/// t0 + start_s <= t <= t0 + end_s where t0 is the first ground-truth time
/// (the EKLT-VIO paper: posyaw on t0+3 s … t0+8 s).

#include <string>
#include <vector>

#include "evio/core/options.h"
#include "evio/core/pose.h"
#include "evio/experiments/trajectory_association.h"

namespace evio::experiments {

enum class AlignmentType { kPosYaw, kSe3, kSim3, kNone };
enum class AlignmentWindow { kAll, kFirstN, kTime };

/// "posyaw", "se3", "sim3", "none".
std::string alignmentTypeName(AlignmentType type);
AlignmentType parseAlignmentType(const std::string& name);  ///< throws Error naming "alignment"

struct AlignmentOptions {
  std::string type = "posyaw";   ///< posyaw | se3 | sim3 | none
  std::string window = "all";    ///< all | first | time
  int first_n = 0;               ///< window "first": number of associated poses (> 1)
  double start_s = 0.0;          ///< window "time": start, s after the first ground-truth time
  double end_s = 0.0;            ///< window "time": end, s after the first ground-truth time
  double min_spread_m = 1e-3;    ///< RMS position spread (of the estimate or the truth) below which the rotation comes from orientations, m

  template <class V>
  void fields(V& v) {
    v("type", type, "posyaw, se3, sim3 or none");
    v("window", window, "all, first or time");
    v("first_n", first_n, "window first: number of associated poses");
    v("start_s", start_s, "window time: start, s after the first ground-truth time");
    v("end_s", end_s, "window time: end, s after the first ground-truth time");
    v("min_spread_m", min_spread_m, "position spread below which rotation comes from orientations, m");
  }
  void validate() const;

  /// The EKLT-VIO paper's alignment: posyaw on t0+3 s … t0+8 s.
  static AlignmentOptions paper();
};

/// A similarity transform (s, R, t): p ↦ s·R·p + t.
struct Similarity {
  double scale = 1.0;
  Mat3 R = Mat3::Identity();
  Vec3 t = Vec3::Zero();

  Vec3 apply(const Vec3& p) const { return scale * (R * p) + t; }
  /// The aligned pose (s R p̂ + t, R R̂).
  Pose apply(const Pose& T) const;
  /// The inverse map applied to a pose: (Rᵀ (p − t) / s, Rᵀ R_T).
  Pose applyInverse(const Pose& T) const;
};

/// The alignment found and how: what every reported number records.
struct Alignment {
  AlignmentType type = AlignmentType::kPosYaw;
  AlignmentOptions options;          ///< as requested
  Similarity transform;              ///< estimate → ground truth
  std::size_t poses_used = 0;        ///< associated poses in the window
  double window_start_s = 0.0;       ///< time span actually used (sequence clock), s
  double window_end_s = 0.0;
  bool rotation_from_orientation = false;

  /// One phrase: "posyaw on t0+3..8 s (1001 poses)", "se3 on all poses (…)", "none".
  std::string describe() const;
};

/// Umeyama (full or yaw-restricted) on point sets: the (s, R, t) minimising
/// Σ‖y_k − (s R x_k + t)‖² for `type`, without the orientation fallback.
/// Throws Error for empty or unequal sets (sim3: when x has no spread).
Similarity umeyama(const std::vector<Vec3>& x, const std::vector<Vec3>& y, AlignmentType type);

/// Finds the alignment of `association` for `options` (validated). Throws
/// evio::Error when the window holds no associated pose, or too few for the type.
Alignment align(const Association& association, TimeNs groundtruth_start_ns, const AlignmentOptions& options);

/// Yaw of a rotation, z-y-x Euler convention: atan2(R10, R00), rad.
double yawOf(const Mat3& R);

/// Rz(θ).
Mat3 rotationZ(double theta_rad);

}  // namespace evio::experiments

#pragma once
/// @file filter_state.h
/// The EKF state of the xVIO-style backend (Mahlknecht et al. 2022, Backend;
/// docs/algorithms.md#error-state): the IMU state, a sliding window of camera
/// pose clones and SLAM features in anchored inverse depth, with the error-state
/// covariance P.
///
/// Error-state layout (the order of P's rows and columns):
///
///   [ δp_W_B(3) δv_W(3) δθ_B(3) δb_g(3) δb_a(3) | clone 0 (δp_W_C, δθ_C) ... clone M-1 | f_0 (δα δβ δρ) ... f_N-1 | δs(2) | δρ_s ]
///
/// With track-error states (FilterState::feature_dim = 5,
/// BackendOptions::slam_track_error_sigma_px > 0) each feature's block is
/// (δα δβ δρ δe_x δe_y): e, normalised image units, the tracker's current
/// error on this feature, a Gauss–Markov process (docs/algorithms.md "Track
/// errors as states").
///
/// with clones oldest first and features in insertion order; δs, the image
/// shift every observation of the newest clone shares (normalised image
/// units, BackendOptions::slam_image_shift_sigma_px, docs/algorithms.md "A
/// shift the features share"), only once it has been added; δρ_s, the
/// scene's inverse depth (1/m), only once it has been added
/// (BackendOptions::slam_scene_depth_share, docs/algorithms.md "The scene's depth as a state").
///
/// Error-state convention (used by every Jacobian of the backend):
///   positions, velocity, biases, feature parameters:  x = x̂ + δx
///   rotations (IMU and clones), right/local perturbation:  R = R̂ · Exp(δθ)
/// so δθ_B is expressed in B and a clone's δθ_C in its camera frame C.

#include <cstdint>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/core/time.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

// ImuState (the mean of the IMU state): measurements.h, where estimates carry it.

/// A camera pose T_W_C cloned into the sliding window at a measurement time.
struct CameraClone {
  std::int64_t id = 0;  ///< unique within a backend run, increasing
  TimeNs t_ns = 0;
  Vec3 p_W_C = Vec3::Zero();
  Quat q_W_C = Quat::Identity();
  /// First estimate (the value when the clone was made, before any update):
  /// where the clone's part of the unobservable yaw direction is evaluated
  /// (FilterState::yawDirection).
  Vec3 p_fej = Vec3::Zero();
  Quat q_fej = Quat::Identity();

  Mat3 R_W_C() const { return q_W_C.toRotationMatrix(); }
};

/// A SLAM feature in anchored inverse depth: the point in the anchor camera
/// frame is p_Ca = [α, β, 1]ᵀ / ρ (α, β normalised image coordinates, ρ the
/// inverse depth in 1/m).
struct SlamFeature {
  FeatureId id = 0;
  std::int64_t anchor_clone_id = 0;
  Vec3 abr = Vec3::Zero();  ///< (α, β, ρ)
  /// The tracker's error on this feature, z = π(h) + e + n, normalised units
  /// (only with track-error states: FilterState::feature_dim = 5).
  Vec2 track_error = Vec2::Zero();
  int gate_failures = 0;    ///< consecutive Mahalanobis gate failures
  /// Time of the clone whose observation last entered an update or the
  /// initialisation (BackendOptions::slam_update_interval_s), ns.
  TimeNs last_update_ns = 0;
  /// That observation, normalised image coordinates
  /// (BackendOptions::slam_update_min_displacement_normalized).
  Vec2 last_update_z = Vec2::Zero();
};

/// Sizes of the error-state blocks.
inline constexpr int kImuDim = 15;
inline constexpr int kCloneDim = 6;
inline constexpr int kFeatureDim = 3;   ///< (α, β, ρ): a feature's block without track-error states
inline constexpr int kTrackErrorDim = 2;  ///< (e_x, e_y) after (α, β, ρ) with them
inline constexpr int kImageShiftDim = 2;  ///< (s_x, s_y), the shared image shift
/// Offsets inside the IMU block.
inline constexpr int kIdxP = 0, kIdxV = 3, kIdxTheta = 6, kIdxBg = 9, kIdxBa = 12;
/// Offsets inside a clone block.
inline constexpr int kCloneP = 0, kCloneTheta = 3;

class FilterState {
 public:
  ImuState imu;
  std::vector<CameraClone> clones;   ///< oldest first
  std::vector<SlamFeature> features;
  /// The scene's inverse depth ρ_s, 1/m: the part of the fixed depth prior's
  /// error that every feature initialised from it shares (ρ_i = ρ_s + δ_i).
  /// The last error-state entry while has_scene_depth.
  bool has_scene_depth = false;
  double scene_rho = 0.0;
  /// ρ_s has taken its one measurement from the triangulated points.
  bool scene_depth_measured = false;
  /// The image shift s (normalised units) that every observation of the
  /// newest clone shares, z = π(h) + s + n: a first-order Gauss–Markov
  /// process with stationary covariance image_shift_cov and correlation time
  /// image_shift_time_s (decayImageShift). When present (has_image_shift),
  /// its two entries follow the last feature's.
  bool has_image_shift = false;
  Vec2 image_shift = Vec2::Zero();
  Mat2 image_shift_cov = Mat2::Zero();
  double image_shift_time_s = 0.05;
  MatX P;                            ///< error-state covariance (dim × dim), symmetric PD
  /// Entries per feature: kFeatureDim, or kFeatureDim + kTrackErrorDim with
  /// track-error states. Set before the first feature is added.
  int feature_dim = kFeatureDim;
  /// Stationary covariance Σ_e of a track error (normalised units²), the
  /// block a new feature's e starts with (feature_dim = 5).
  Mat2 track_error_cov = Mat2::Zero();
  /// Correlation time τ of the track errors, s (feature_dim = 5): also the
  /// correlation of one MSCKF track's observations (msckf_update.h).
  double track_error_time_s = 0.5;
  bool hasTrackErrors() const { return feature_dim > kFeatureDim; }

  /// Total error-state dimension 15 + 6 M + feature_dim N (+ 2 with the image
  /// shift, + 1 with the scene depth).
  int dim() const { return kImuDim + kCloneDim * static_cast<int>(clones.size()) +
                           feature_dim * static_cast<int>(features.size()) + (has_image_shift ? kImageShiftDim : 0) +
                           (has_scene_depth ? 1 : 0); }
  /// First covariance index of s (requires has_image_shift).
  int imageShiftIndex() const { return featureIndex(features.size()); }
  /// Covariance index of ρ_s (requires has_scene_depth).
  int sceneDepthIndex() const { return featureIndex(features.size()) + (has_image_shift ? kImageShiftDim : 0); }
  /// First covariance index of clone i (position in `clones`).
  int cloneIndex(std::size_t i) const { return kImuDim + kCloneDim * static_cast<int>(i); }
  /// First covariance index of feature j (position in `features`).
  int featureIndex(std::size_t j) const {
    return kImuDim + kCloneDim * static_cast<int>(clones.size()) + feature_dim * static_cast<int>(j);
  }
  /// Whether clone c (position in `clones`) is the newest: the set being processed.
  bool isNewestClone(std::size_t c) const { return c + 1 == clones.size(); }
  /// Position of the clone with `id` in `clones`, or -1.
  int findClone(std::int64_t id) const;
  /// Position of the feature with `id` in `features`, or -1.
  int findFeature(FeatureId id) const;

  /// Applies an error-state correction δx (size dim()) to the mean by the
  /// convention above (rotations: R ← R Exp(δθ)).
  void correct(const VecX& dx);

  /// Appends a clone whose error is δc = J δx (J: 6 × dim()), i.e. P grows by
  ///   [P, P Jᵀ; J P, J P Jᵀ]  (the clone is inserted after the existing clones).
  void addClone(const CameraClone& clone, const Eigen::Matrix<double, kCloneDim, Eigen::Dynamic>& J);
  /// Removes clone i and its rows/columns (marginalisation).
  void removeClone(std::size_t i);
  /// Appends a feature with covariance P_ff (3×3) and cross-covariance P_fx (3 × dim()).
  /// With track-error states its e starts at zero with Σ_e, and the bearing,
  /// taken from an observation z = (α, β) + e + n, carries −e:
  /// Cov(δ(α,β)) += Σ_e, Cov(δ(α,β), δe) = −Σ_e, e independent of the rest.
  void addFeature(const SlamFeature& f, const Mat3& P_ff, const Eigen::Matrix<double, 3, Eigen::Dynamic>& P_fx);
  /// Removes feature j and its rows/columns (marginalisation).
  void removeFeature(std::size_t j);
  /// Adds ρ_s = rho with variance `variance`, uncorrelated with the rest.
  void addSceneDepth(double rho, double variance);
  /// Adds the image shift s = 0 with its stationary covariance `cov` (normalised
  /// units²), uncorrelated with the rest, after the features (before ρ_s).
  void addImageShift(const Mat2& cov, double time_s);

  /// P ← (P + Pᵀ)/2.
  void symmetrize();

  /// The unobservable global-yaw direction n of the error state: a rotation
  /// by ε about the vertical e_z through the centroid c of the position
  /// states (IMU and clones) moves every pose; IMU part at `imu`
  /// (δp = e_z × (p − c), δv = e_z × v, δθ = R_W_Bᵀ e_z), clone parts at
  /// their first estimates (δp_C = e_z × (p_C − c), δθ_C = R_W_Cᵀ e_z), zero
  /// for the anchored features, the scene depth and the biases. Global translation t is
  /// unobservable too, and every model of the backend is exactly invariant to
  /// it (H t = 0 at any linearisation point); rotating about the centroid makes
  /// n orthogonal to t, so the constraint H ← H − (H n) nᵀ/|n|² keeps H t = 0.
  /// (About the origin instead, nᵀt ≠ 0 and the projection itself gave the
  /// rows translation information, ‖H t‖ up to 3 % of ‖H‖, which the filter
  /// turned into spurious yaw information.)
  VecX yawDirection(const ImuState& imu) const;

  /// The error-state difference x ⊟ ref (the inverse of correct(): ref with
  /// correct(x ⊟ ref) gives x). Both states must have the same clones,
  /// features, image shift and scene depth; rotations: Log(R_refᵀ R).
  VecX minus(const FilterState& ref) const;
};

/// With the image shift, an observation of the newest clone is
/// z = π(h) + s + n: its whitened rows at `row` (whitening W, 2 rows of H, r)
/// gain W on s's columns, and its whitened residual loses W ŝ. Nothing for
/// an older clone's observation (it saw an earlier shift, which the state no
/// longer holds and its noise carries) or without the shift.
void addImageShiftToRows(const FilterState& state, std::size_t c, const Mat2& W, Eigen::Index row, MatX* H, VecX* r);

/// Removes `size` rows and columns starting at `index` from a square matrix.
void removeRowsCols(MatX& P, int index, int size);

}  // namespace evio::estimator

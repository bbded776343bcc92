#pragma once
/// @file gyro_bias_from_tracks.h
/// The gyroscope bias from the first second of feature tracks
/// (docs/algorithms.md#gyroscope-bias-from-tracks), before the filter's first
/// visual update, so that the filter starts near the bias instead of learning
/// a turn-on bias of several °/s through its linearisation.
///
/// Frames: B the body (IMU), C the camera, R_B_C the camera's attitude in B.
/// A gyroscope reading is ω_m = ω + b_g + n. Between two keyframes i < j the
/// camera turns by
///   R_Ci_Cj(b) = R_B_Cᵀ · ∏_k Exp((ω̄_k − b) Δt_k) · R_B_C,
/// the product over the IMU intervals in [t_i, t_j] (ω̄_k: the mean of the
/// interval's end readings, readings interpolated at t_i and t_j). A point
/// seen along the unit bearings f_i (in Ci) and f_j (in Cj) lies in the
/// epipolar plane through the translation t_ij, so with
///   n_k(b) = f_i,k × R_Ci_Cj(b) f_j,k          (normal of that plane)
/// every feature k of the pair gives tᵀ n_k = 0. Whatever t is, the rotation
/// alone is scored by
///   λ_min( Σ_k n_k n_kᵀ ) = min_{‖t‖=1} Σ_k (tᵀ n_k)²
/// (the eigenvalue form of the epipolar constraint; Kneip & Lynen 2013), which
/// is zero for the true rotation with noiseless bearings, also when t = 0.
///
/// Of K keyframes, keyframe i pairs with keyframe i + ⌈K/2⌉: no keyframe is in
/// two pairs, so white bearing errors leave the pairs independent (pairs that
/// share a keyframe have anti-correlated rotation errors, and a covariance
/// that ignores it is several times too large), and each pair spans half the
/// window, where the bias's rotation is largest against the bearing noise.
/// The bias minimises the sum of that cost over the pairs, by Gauss–Newton
/// on the residuals r_k = tᵀ n_k / s_k, each pair's t the minimising
/// eigenvector at b (variable projection). The Jacobian lets t follow b: with
/// t held during a step, the steps crawl along the valley where a rotation
/// error trades off against a tilted translation (a narrow field of view over
/// a plane) and stopped 4°/s from the truth on a simulated poster sequence.
/// Even so the cost keeps separate minima along that valley, several °/s
/// apart on the simulated poster and shapes (narrow field of view over a
/// plane): from the prior mean alone, 3 of 10 KLT-VIO runs on poster_6dof
/// ended 5–6°/s off. So Gauss–Newton runs from the lowest points of the
/// summed eigenvalue cost on a grid over the prior's box (the rotations to
/// first order in the bias, every feature of equal weight), and the solution
/// whose residuals have the smallest robust spread is kept. s_k is r_k's
/// first-order standard deviation per unit bearing noise, so the residuals
/// are equally weighted (Sampson's normalisation). Residuals beyond
/// outlier_sigmas · σ are dropped once and the solve re-run.
///
/// That two-view estimate is biased under bearing noise along the same
/// valley (1.88 °/s mean error at 0.5 px on a narrow view of a wall), so it
/// only starts a bundle adjustment of all keyframes
/// (refineGyroBiasByBundleAdjustment: reprojection errors, camera centres and
/// points free, rotations from the gyroscope), which gives the tracks'
/// estimate and its covariance σ² (JᵀJ)⁻¹. A split-half check widens that
/// covariance when the two halves of the window disagree more than it allows
/// (track errors correlated over the window). The estimate is then fused with
/// the prior N(b₀, P₀) the filter already had.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/imu_sample.h"
#include "evio/core/time.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

struct GyroBiasFromTracksOptions {
  /// Minimum features two keyframes must share for their pair to count.
  int min_features = 8;
  /// Residuals beyond this many σ are dropped before the final solve.
  double outlier_sigmas = 3.0;
  /// Gauss–Newton iterations per solve at most.
  int max_iterations = 20;
  /// The search for starting points (see above): a grid over the prior's
  /// ±grid_sigmas · σ box with grid_steps_per_sigma points per σ and axis,
  /// and Gauss–Newton from its `starts` lowest points.
  double grid_sigmas = 3.0;
  int grid_steps_per_sigma = 4;
  int starts = 6;
  /// The bundle adjustment's features: seen at this many keyframes or more.
  int min_keyframes_per_feature = 3;
  /// Refine by the bundle adjustment (refineGyroBiasByBundleAdjustment).
  bool bundle_adjustment = true;
  /// Inflate the bundle adjustment's covariance by the split-half check.
  bool split_half_check = true;
};

/// Unit bearings of the features seen at one keyframe, sorted by id.
struct BearingKeyframe {
  TimeNs t_imu_ns = 0;                              ///< IMU clock
  std::vector<std::pair<FeatureId, Vec3>> bearings_C;  ///< camera frame, unit norm
};

struct GyroBiasEstimate {
  Vec3 b_g = Vec3::Zero();             ///< posterior mean, rad/s
  Mat3 covariance = Mat3::Zero();      ///< posterior covariance, (rad/s)²
  bool from_tracks = false;            ///< false: too few pairs, the prior returned unchanged
  int pairs = 0;                       ///< keyframe pairs of the two-view stage
  int residuals = 0;                   ///< its feature residuals in the final solve
  int outliers = 0;                    ///< its residuals dropped
  double bearing_sigma_rad = 0.0;      ///< bearing noise σ from the residuals (of the bundle adjustment when it ran)
  Vec3 data_b_g = Vec3::Zero();        ///< the tracks' estimate alone (before the prior)
  Mat3 data_covariance = Mat3::Zero(); ///< its covariance (inflated by the split-half check)
  /// The split-half check's q (gyro_bias_from_tracks.cpp): about 1 when the
  /// covariance fits the data; 0 when not run.
  double split_half_q = 0.0;
  /// The window's IMU was at rest (static_initializer.h restMeasurement): the
  /// biases came from its mean readings instead of the tracks, and the
  /// filter starts with their covariance as well.
  bool at_rest = false;
  double rest_s = 0.0;  ///< the readings' span, s
  /// At rest only from the window's start until it moved (still_prefix.h):
  /// the filter starts at the prefix's end, rest_s after the window's start.
  bool rest_prefix = false;
  /// The images' still test over the rest (still_prefix.h imageRotationRate):
  /// features used and ωᵀ C⁻¹ ω (0 features: not run or too few).
  int rest_image_features = 0;
  double rest_image_chi2 = 0.0;
  /// At rest the accelerometer bias comes from the mean force too (with the
  /// tilt): its posterior mean, m/s², and covariance, (m/s²)².
  Vec3 rest_b_a = Vec3::Zero();
  Mat3 rest_b_a_covariance = Mat3::Zero();
  /// The bias block of the covariance the filter started with, (rad/s)²
  /// (set by the pipeline: the prior's, or this estimate's; see
  /// init.gyro_bias_window_sigma).
  Mat3 filter_start_covariance = Mat3::Zero();
};

/// The bundle adjustment's result (refineGyroBiasByBundleAdjustment).
struct BundleBiasEstimate {
  bool valid = false;
  Vec3 b_g = Vec3::Zero();
  Mat3 covariance = Mat3::Zero();   ///< the bias block of σ² (JᵀJ)⁻¹
  double bearing_sigma_rad = 0.0;   ///< σ from the residuals
  int observations = 0;             ///< used, after the gate
  int features = 0;
  int outliers = 0;                 ///< observations gated
};

/// The bias by a bundle adjustment of all keyframes from b_start
/// (gyro_bias_bundle.cpp): rotations from the gyroscope with the bias,
/// camera centres and anchored inverse depths free, the reprojection error
/// of every observation in angles. The two-view cost above is biased along
/// the rotation–translation valley under bearing noise (a narrow view of a
/// wall: 1.88 °/s mean error at 0.5 px, 0.37 °/s after this); this is
/// nearly not, and starts in the valley's right part from the two-view
/// estimate. Invalid with fewer than min_features
/// features at min_keyframes_per_feature keyframes.
BundleBiasEstimate refineGyroBiasByBundleAdjustment(const std::vector<BearingKeyframe>& keyframes,
                                                    const ImuSamples& imu, const Mat3& R_B_C, const Vec3& b_start,
                                                    const GyroBiasFromTracksOptions& options = {});

/// R_Bi_Bj(b): the body's rotation from t0 to t1 (IMU clock) integrated from
/// `imu` (time-ordered, covering [t0, t1]) with the bias b removed.
Mat3 integrateGyroRotation(const ImuSamples& imu, TimeNs t0_ns, TimeNs t1_ns, const Vec3& b_g);

/// The estimate from `keyframes` (time-ordered; paired as above) and the gyroscope readings `imu` covering them. Returns the prior
/// (from_tracks false) when fewer than two pairs share min_features features.
GyroBiasEstimate estimateGyroBiasFromTracks(const std::vector<BearingKeyframe>& keyframes, const ImuSamples& imu,
                                            const Mat3& R_B_C, const Vec3& prior_b_g, const Mat3& prior_covariance,
                                            const GyroBiasFromTracksOptions& options = {});

}  // namespace evio::estimator

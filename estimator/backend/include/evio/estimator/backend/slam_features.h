#pragma once
/// @file slam_features.h
/// SLAM features in anchored inverse depth (Mahlknecht et al. 2022, Backend;
/// docs/algorithms.md#slam-features): their measurement, their two ways into the
/// state, and re-anchoring when the window slides.

#include <cstddef>
#include <functional>

#include "evio/core/eigen_types.h"
#include "evio/estimator/backend/feature_track.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

/// Residual r = z − π(h) of SLAM feature j observed at z in clone c (positions
/// in state.features / state.clones) and its Jacobian H (2 × dim) over the
/// anchor clone, the observing clone and the feature (visual_models.h); with
/// track-error states r = z − π(h) − e, and with the image shift, when c is
/// the newest clone (the set being processed), r = z − π(h) − s (an older
/// clone's observation shares an earlier shift the state no longer holds,
/// which its noise carries). False when the feature is not in front of the clone.
bool slamResidual(const FilterState& state, std::size_t j, std::size_t c, const Vec2& z,
                  Eigen::Matrix<double, 2, Eigen::Dynamic>* H, Vec2* r);

/// Covariance (2 × 2, normalised image units) of the second-order term of
/// SLAM feature j's observation in clone c that the EKF's linearisation drops
/// (docs/algorithms.md#second-order-depth-term). With h = R_iᵀ(R_a b + ρ dp),
/// dp = p_a − p_i, the product of the inverse depth and the clones' errors
///   δh₂ = δρ · g,  g = R_iᵀ(δp_a − δp_i) + [R_iᵀ dp]× δθ_i = G δx,
/// is bilinear in Gaussian errors, so (Isserlis) its covariance is exactly
///   Cov(δh₂) = σ_ρ² G P_xx Gᵀ + (G P_xρ)(G P_xρ)ᵀ,
/// mapped to the image by Π = ∂π/∂h. It matters for depth-prior features
/// (σ_ρ of half of ρ): a 1 m⁻¹ prior and 1 cm between the clones give
/// about 0.005 normalised, a pixel at f = 200 px. Zero in the anchor (dp = 0
/// and δp_a = δp_i). False when the point is not in front of the clone.
bool slamSecondOrderCovariance(const FilterState& state, std::size_t j, std::size_t c, Mat2* cov);

/// The whitening of an observation whose covariance σ_z² W⁻¹W⁻ᵀ (W its
/// whitening, feature_track.h) grows by `extra`: W' with
/// W'(σ_z² W⁻¹W⁻ᵀ + extra)W'ᵀ = σ_z² I.
Mat2 whitenWithExtraCovariance(const Mat2& whiten, double sigma_z, const Mat2& extra);

/// The variance factor κ of one of a run of samples dt_s apart whose common
/// error is a first-order Gauss–Markov process with time constant time_s:
/// with ρ = exp(−dt/τ), N such samples carry as much information about a
/// constant as N (1 − ρ)/(1 + ρ) independent ones, so each counts as one
/// sample with its variance times
///   κ = (1 + ρ)/(1 − ρ) = coth(dt / 2τ)   (≈ 2τ/dt for dt ≪ τ, → 1 for dt ≫ τ).
/// 1 when time_s ≤ 0 (no correlation); +∞ when dt_s ≤ 0 (the same instant).
double correlatedSampleVarianceFactor(double dt_s, double time_s);

/// The track-error states (filter_state.h, feature_dim = 5) over dt_s: each
/// e is a first-order Gauss–Markov process with correlation time time_s and
/// stationary covariance Σ_e (state.track_error_cov), so exactly, for any dt,
///   e ← φ e,  P's e rows and columns × φ,  P_ee += (1 − φ²) Σ_e,  φ = exp(−dt/τ).
/// No-op without track-error states or for dt ≤ 0.
void decayTrackErrors(FilterState& state, double dt_s, double time_s);

/// The image shift (filter_state.h, has_image_shift) over dt_s, the same
/// exact Gauss–Markov step with its own time constant and covariance:
///   s ← φ s,  P's s rows and columns × φ,  P_ss += (1 − φ²) Σ_s,  φ = exp(−dt/τ_s).
/// No-op without the shift or for dt ≤ 0.
void decayImageShift(FilterState& state, double dt_s);

/// Depth-prior initialisation (Montiel et al. 2006; xVIO): anchor = clone c,
/// (α, β) = z, ρ = rho0, with covariance diag(Σ_z, σ_ρ0²) (Σ_z = σ_z² W⁻¹W⁻ᵀ,
/// W the observation's whitening, feature_track.h; σ_z² I when W = I) and zero
/// cross-covariance — the parameters are relative to the anchor clone, whose
/// own error is in the state, so the new feature is independent of it. With
/// the image shift, when c is the newest clone, z = b + s + n gives
/// (α, β) = z − ŝ and δ(α, β) = −δs − n (both functions).
void addSlamFeatureWithPrior(FilterState& state, FeatureId id, std::size_t c, const Vec2& z, double rho0,
                             double sigma_rho0, double sigma_z, const Mat2& whiten = Mat2::Identity());

/// The same with the depth from the scene's inverse depth ρ_s (the state
/// must have it): ρ = ρ_s + δ, δ independent with σ_δ = sigma_delta, so
/// ρ's variance is P_ss + σ_δ² and its cross-covariance with everything is
/// ρ_s's (docs/algorithms.md "The scene's depth as a state").
void addSlamFeatureFromSceneDepth(FilterState& state, FeatureId id, std::size_t c, const Vec2& z,
                                  double sigma_delta, double sigma_z, const Mat2& whiten);

/// A prior on a new feature's inverse depth, ρ ~ N(rho, sigma²), 1/m.
struct InverseDepthPrior {
  double rho = 0.0;
  double sigma = 0.0;
};

/// Result of the triangulated initialisation.
enum class SlamInitOutcome { kOk, kDegenerate, kGateFailed, kUpdateFailed };

/// Initialisation from a triangulated track (Li & Mourikis 2012, the "delayed"
/// initialisation), anchored in the track's last clone with triangulated
/// parameters abr. Stacking all observations, r ≈ H_x δx + H_f δf + n with the
/// QR split H_f = [Q1 Q2][R1; 0]:
///   Q1ᵀ r = Q1ᵀ H_x δx + R1 δf + Q1ᵀ n  ⇒ δf = R1⁻¹(Q1ᵀ r − H1 δx − n1), H1 = Q1ᵀ H_x,
/// so the feature enters with mean abr + R1⁻¹ Q1ᵀ r, covariance
///   P_ff = R1⁻¹ (H1 P H1ᵀ + σ² I) R1⁻ᵀ,  P_fx = −R1⁻¹ H1 P,
/// and the rest (Q2ᵀ H_x, Q2ᵀ r) is an ordinary update, χ²-gated with threshold
/// `chi2_threshold(dof)`. Needs at least 2 observations. `constrain(H)` is
/// applied to H_x before the split (the backend's observability constraint;
/// pass a no-op to disable). With `prior`, the stack holds one more row,
/// the depth prior ρ0 = ρ + w (w ~ N(0, σ_ρ0²)) whitened to σ²: the
/// initialisation from a track too short to fix its depth alone
/// (docs/algorithms.md "Depth prior with the track"); abr should then be
/// refineWithDepthPrior's answer.
template <class Chi2, class Constrain>
SlamInitOutcome addSlamFeatureTriangulated(FilterState& state, const FeatureTrack& track, const Vec3& abr,
                                           double sigma2, bool joseph, const Chi2& chi2_threshold,
                                           const Constrain& constrain, const InverseDepthPrior* prior = nullptr);

/// Re-anchors feature j onto clone `to` (positions in the state): the mean by
/// reanchorFeature() and the covariance by P ← T P Tᵀ, T the identity with the
/// feature's rows replaced by [∂f'/∂x_from, ∂f'/∂x_to, ∂f'/∂f]. The feature's
/// world point and its covariance are unchanged. False (state unchanged) when
/// the point is not in front of `to`. When `yaw_direction` is non-null (the
/// backend's observability constraint), the rows of T are projected so that the
/// feature gains no component along it (T n = n for the anchored parameters, whose
/// own component is zero).
bool reanchorSlamFeature(FilterState& state, std::size_t j, std::size_t to, const VecX* yaw_direction = nullptr);

// --- implementation of the template ------------------------------------------------

/// Non-template part of addSlamFeatureTriangulated: builds the feature's mean,
/// P_ff, P_fx and the remaining update (H2, r2). False when degenerate.
bool splitTriangulatedInit(const FilterState& state, const FeatureTrack& track, const Vec3& abr, double sigma2,
                           SlamFeature* f, Mat3* P_ff, Eigen::Matrix<double, 3, Eigen::Dynamic>* P_fx, MatX* H2,
                           VecX* r2, const std::function<void(MatX*)>& constrain,
                           const InverseDepthPrior* prior = nullptr);
double slamMahalanobis(const FilterState& state, const MatX& H, const VecX& r, double sigma2);
bool slamUpdate(FilterState& state, const MatX& H, const VecX& r, double sigma2, bool joseph);

template <class Chi2, class Constrain>
SlamInitOutcome addSlamFeatureTriangulated(FilterState& state, const FeatureTrack& track, const Vec3& abr,
                                           double sigma2, bool joseph, const Chi2& chi2_threshold,
                                           const Constrain& constrain, const InverseDepthPrior* prior) {
  SlamFeature f;
  Mat3 P_ff;
  Eigen::Matrix<double, 3, Eigen::Dynamic> P_fx;
  MatX H2;
  VecX r2;
  if (!splitTriangulatedInit(state, track, abr, sigma2, &f, &P_ff, &P_fx, &H2, &r2, constrain, prior))
    return SlamInitOutcome::kDegenerate;
  if (r2.size() > 0 && slamMahalanobis(state, H2, r2, sigma2) > chi2_threshold(static_cast<int>(r2.size())))
    return SlamInitOutcome::kGateFailed;
  const int k = state.featureIndex(state.features.size());  // where the feature goes (before s and ρ_s)
  state.addFeature(f, P_ff, P_fx);
  if (r2.size() == 0) return SlamInitOutcome::kOk;
  MatX H2_new = MatX::Zero(H2.rows(), state.dim());  // the new feature's columns are zero
  H2_new.leftCols(k) = H2.leftCols(k);
  H2_new.rightCols(H2.cols() - k) = H2.rightCols(H2.cols() - k);
  H2.swap(H2_new);
  return slamUpdate(state, H2, r2, sigma2, joseph) ? SlamInitOutcome::kOk : SlamInitOutcome::kUpdateFailed;
}

}  // namespace evio::estimator

#pragma once
/// @file eklt_cost.h
/// The EKLT alignment cost for one batch of events (Gehrig et al., IJCV 2019;
/// Mahlknecht et al. 2022, the EKLT optimisation; docs/algorithms.md#eklt).
///
/// Parameters p = (θ, tx, ty, φ): a rigid warp W(u; θ, t) = R(θ) u + t that
/// maps a patch offset u (px, relative to the point around which the batch
/// was accumulated) into the frame where the feature was initialised, and
/// the flow direction v(φ) = (cos φ, sin φ) in the current image.
///
/// For every patch pixel u (row i, column j: u = (j − h, i − h), h = (P−1)/2):
///   predicted increment  a(u) = −g(W(u))ᵀ R(θ) v(φ),   g = ∇L of the template
///   (the template gradient seen in the current image is R(θ)ᵀ g, so
///    −(Rᵀg)·v = −g·(R v); this is the linearised event generation model
///    ΔL = −∇L·v Δt with the unobservable magnitude |v|Δt dropped);
///   residual             r(u) = a(u)/‖a‖ − m(u),
/// with m the measured increment (events with polarity ±1, bilinearly
/// splatted) normalised to ‖m‖ = 1. The cost is Ceres' ½‖r‖² = 1 − ρ with
/// ρ = âᵀm the normalised correlation, so the tracking quality 1 − cost/2
/// equals (1 + ρ)/2 ∈ [0, 1].

#include "evio/core/eigen_types.h"
#include "evio/estimator/frontend/gradient_template.h"

namespace evio::estimator {

/// The data of one optimisation.
struct EkltBatch {
  const GradientTemplate* templ = nullptr;  ///< gradient of the initialisation frame
  const float* measured = nullptr;          ///< P×P row-major, unit L2 norm
  int patch_size = 0;                       ///< P (odd)
  /// Evaluate the sums with the Jacobian in single precision, sixteen patch
  /// pixels at a time, where the warp's lookups lie inside the template
  /// (eklt_cost_single.cpp); the same bits on every x86-64 CPU. Else, and
  /// without the Jacobian, double precision.
  bool single_precision = false;
};

/// Cost and Gauss–Newton quantities at one parameter vector.
struct EkltEvaluation {
  double cost = 0.0;      ///< ½‖r‖²
  double rho = 0.0;       ///< âᵀm
  double abs_sum = 0.0;   ///< Σ|a(u)| (unnormalised), for the adaptive batch size
  Mat4 jtj = Mat4::Zero();  ///< JᵀJ, J = ∂r/∂p
  Vec4 jtr = Vec4::Zero();  ///< Jᵀr
};

/// Evaluates the cost (and JᵀJ, Jᵀr when `with_jacobian`) without forming r
/// or J: with n = ‖a‖, â = a/n, s = Σ â ∂a/∂p:
///   JᵀJ = (Σ ∂a/∂pᵀ∂a/∂p − s sᵀ)/n²,   Jᵀr = (ρ s − Σ m ∂a/∂p)/n.
/// Returns false when the predicted increment vanishes (n = 0).
bool evaluateEklt(const EkltBatch& batch, const Vec4& p, bool with_jacobian, EkltEvaluation* out);

/// The residual vector r (P² entries, row-major) and optionally d_r_d_p
/// (P² × 4), formed explicitly; for tests and the numeric-Jacobian check.
bool ekltResiduals(const EkltBatch& batch, const Vec4& p, VecX* r, MatX* d_r_d_p = nullptr);

/// Where patch offset u maps, and the feature position this implies: the
/// patch centre (u = 0) in the current image is the point that the warp
/// sends to the template point x0, c = c_acc + R(θ)ᵀ (x0 − t).
Vec2 ekltFeaturePosition(const Vec4& p, const Vec2& accumulation_centre, const Vec2& x0);

/// The floor of the position σ for a solution with this cost (px): σ_min,
/// raised in proportion for fits worse than the reference cost, up to the cap,
///   σ_floor = min(σ_min · max(1, cost / cost_ref), σ_max)
/// (cost_ref ≤ 0: σ_min). Measured on EKLT's points against their truth (the
/// lag removed; poster_6dof and mars_yard_circle, seed 101), the error's
/// variance per axis grows as the square of the cost: 6.3 and 4.9 px² · cost²
/// with no intercept (docs/consistency.md "A covariance floor that follows
/// the fit").
double ekltSigmaFloor(double cost, double sigma_min_px, double sigma_max_px, double cost_ref);

/// The covariance of the feature position ekltFeaturePosition(p, c_acc, x0)
/// at a minimum p of the cost (docs/algorithms.md#eklt-measurement-covariance):
/// the Gauss–Newton (Laplace) covariance of the least-squares estimate,
///   Σ_p = (JᵀJ / σ_r² + Λ₀)⁻¹,   σ_r² = ‖r‖² / (P² − 4) = 2·cost / (P² − 4),
/// with Λ₀ = diag(1/π², 1/σ_max², 1/σ_max², 1/π²) a weak prior on (θ, tx, ty, φ)
/// that bounds the directions the patch does not constrain (along a straight
/// edge JᵀJ has no curvature: the position is uncertain along the edge up to
/// σ_max), mapped to the position c = c_acc + R(θ)ᵀ (x0 − t):
///   Σ_c = G Σ_p Gᵀ,  G = ∂c/∂p = [∂Rᵀ/∂θ (x0 − t), −Rᵀ, 0]   (px²).
/// Finally each eigenvalue of Σ_c is clamped to [σ_min², σ_max²] (σ_min: the
/// floor, fixed or from ekltSigmaFloor; it must not exceed σ_max).
/// `eval` must hold JᵀJ and the cost at p (evaluateEklt with_jacobian).
Mat2 ekltPositionCovariance(const EkltEvaluation& eval, const Vec4& p, const Vec2& x0, int patch_size,
                            double sigma_min_px, double sigma_max_px);

namespace detail {
/// For tests: does this CPU take the AVX path of the bicubic template
/// lookup, and the lookup itself (value g and ∂g/∂W at template point W,
/// its 4×4 taps inside the template) through the AVX path (`avx` and the CPU
/// has it) or the SSE2 one. Both must give the same bits.
bool ekltSampleHasAvx();
void ekltSampleInside(const GradientTemplate& templ, const Vec2& W, Vec2* g, Mat2* dg, bool avx);
/// For tests: evaluateEklt with the Jacobian through the highest
/// instruction set the CPU has up to `simd_limit` (0 the x86-64 baseline,
/// 1 AVX, 2 AVX-512F for the single-precision lanes); every path must give
/// the same bits. ekltSimdLevel: the level that limit gives on this CPU.
bool evaluateEkltPath(const EkltBatch& batch, const Vec4& p, int simd_limit, EkltEvaluation* out);
int ekltSimdLevel(int simd_limit);
}  // namespace detail

}  // namespace evio::estimator

#pragma once
/// @file triangulation.h
/// Triangulation of a feature from its observations in the sliding window
/// (docs/algorithms.md#triangulation: Gauss–Newton in inverse depth, 10 iterations, tol 1e-5).
///
/// 1. Linear start: the point p minimising Σ_i ‖(I − b_i b_iᵀ)(p − p_i)‖²,
///    b_i = R_i [z_i; 1]/‖·‖ the unit rays, p_i the clone positions.
/// 2. Gauss–Newton on the anchored inverse-depth parameters (α, β, ρ) of the
///    anchor clone, minimising Σ_i ‖z_i − π(h_i(α, β, ρ))‖² (visual_models.h),
///    stopping when the step is below tolerance · ‖(α, β, ρ)‖.
/// 3. The inverse depth's standard deviation from the observations alone,
///    σ_ρ = σ_z √[(JᵀJ)⁻¹]_ρρ with J the Jacobian at the solution and σ_z one
///    observation's noise: how much the track itself says about the depth
///    (infinite without baseline, e.g. in rotation-only motion).

#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

struct TriangulationOptions {
  int max_iterations = 10;       ///< Gauss–Newton iterations
  double tolerance = 1e-5;       ///< relative step size that ends the iteration
  double min_depth_m = 0.05;     ///< nearer points (in any observing clone) are rejected
  double max_depth_m = 1000.0;   ///< farther points (in the anchor) are rejected
  /// Residual bound: the RMS reprojection error after convergence must be
  /// below this, in normalised units (0: no bound).
  double max_rms_residual = 0.0;
  /// For knowsDepth(): one observation's noise σ_z (normalised units) and the
  /// largest σ of ρ a usable triangulation may have, 1/m (0: no bound).
  double sigma_z = 0.0;
  double max_sigma_rho = 0.0;
};

struct TriangulationResult {
  Vec3 abr = Vec3::Zero();  ///< (α, β, ρ) in the anchor clone
  Vec3 p_W = Vec3::Zero();  ///< the same point in W
  int iterations = 0;
  double rms_residual = 0.0;  ///< normalised units
  /// σ of ρ from the observations alone for a noise of 1 normalised unit per
  /// coordinate (multiply by σ_z), 1/m; infinity when ρ is unobservable.
  double sigma_rho_unit = 0.0;
};

/// Triangulates from observations z[i] in clones[i] (at least 2), anchored in
/// clones[anchor]. Returns false (result unspecified) when the linear system is
/// degenerate, the point is behind or too near/far, or GN diverges.
bool triangulateFeature(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                        std::size_t anchor, const TriangulationOptions& options, TriangulationResult* result);

/// The maximum a posteriori (α, β, ρ) of a feature anchored in clones[anchor]
/// from its observations z[i] (whitening whiten[i] to σ_z², feature_track.h)
/// and a prior ρ ~ N(rho0, sigma_rho0²), the clone poses held fixed:
/// Gauss–Newton on
///   Σ_i ‖W_i (z_i − π(h_i(α, β, ρ)))‖² + (σ_z/σ_ρ0)² (ρ − ρ0)²
/// from (z_anchor, ρ0), each step halved until the cost does not rise (at
/// most 10 times). Where the track has no parallax the data say nothing about ρ and
/// the answer is ρ0; with some parallax ρ moves as far as the data outweigh
/// the prior, which one linearised update at ρ0 does not do when ρ0 is far
/// off. False when a step fails or the point ends behind or nearer than
/// options.min_depth_m to a clone (docs/algorithms.md "Depth prior with the track").
bool refineWithDepthPrior(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                          const std::vector<Mat2>& whiten, std::size_t anchor, double rho0, double sigma_rho0,
                          double sigma_z, const TriangulationOptions& options, Vec3* abr);

/// Whether the track's observations fix the inverse depth to within
/// options.max_sigma_rho: σ_z · sigma_rho_unit ≤ max_sigma_rho (always true
/// when max_sigma_rho is 0).
bool knowsDepth(const TriangulationResult& result, const TriangulationOptions& options);

/// Rotation-compensated disparity of a track (docs/algorithms.md#triangulation, the parallax test):
/// the largest distance, in normalised units, between the observation in the
/// last clone and the rays of the other observations rotated into it,
///   max_i ‖π(R_lastᵀ R_i [z_i; 1]) − z_last‖.
/// Multiply by the focal length for pixels.
double rotationCompensatedDisparity(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z);

}  // namespace evio::estimator

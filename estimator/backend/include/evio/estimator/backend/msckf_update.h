#pragma once
/// @file msckf_update.h
/// The MSCKF measurement of one feature track (Mourikis & Roumeliotis 2007;
/// docs/algorithms.md#msckf-features): triangulate the point p_W from the track's
/// observations in the window (triangulation.h), linearise all observations,
///   r = z − π(R_iᵀ (p̂_W − p_i)) ≈ H_x δx + H_f δp_W + n,
/// and project on the left null space of H_f (ekf_update.h) so that the
/// 2n − 3 residuals r_o = Q2ᵀ r constrain the clone poses only.
/// With track-error states (filter_state.h) the observations of one track
/// share the tracker's error, a Gauss–Markov process: the whitened rows'
/// noise is C = σ_z² I + [exp(−|t_i − t_j|/τ) W_i Σ_e W_jᵀ]_ij, and the
/// rows are whitened by L⁻¹ (C = σ_z² L Lᵀ) before the projection.

#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/estimator/backend/feature_track.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/backend/triangulation.h"

namespace evio::estimator {

/// kNoParallax: the rotation-compensated disparity is below the minimum;
/// kDepthUnknown: the track has the disparity but its triangulation fixes
/// the depth worse than the prior would (knowsDepth).
enum class MsckfOutcome { kOk, kTooShort, kNoParallax, kDepthUnknown, kTriangulationFailed, kProjectionFailed };

struct MsckfResidual {
  MatX H;               ///< (2n − 3) × dim, null-space projected
  VecX r;               ///< 2n − 3
  Vec3 p_W = Vec3::Zero();  ///< the triangulated point
};

/// The clones, their positions in state.clones and the observations of a
/// track whose clones are still in the window (observations of missing clones
/// are skipped), and when asked their whitening matrices (feature_track.h).
void gatherTrack(const FilterState& state, const FeatureTrack& track, std::vector<CameraClone>* clones,
                 std::vector<std::size_t>* clone_positions, std::vector<Vec2>* z,
                 std::vector<Mat2>* whiten = nullptr);

/// The null-space projected MSCKF residual of `track`. min_parallax is the
/// rotation-compensated disparity (normalised units) the track must exceed;
/// a triangulation that fails knowsDepth(·, triangulation) is kDepthUnknown.
/// sigma2_z: σ_z², the noise of one whitened row, needed only with
/// track-error states (the shared error's whitening; must then be positive).
MsckfOutcome msckfResidual(const FilterState& state, const FeatureTrack& track, double min_parallax,
                           const TriangulationOptions& triangulation, MsckfResidual* out, double sigma2_z = 0.0);

/// The rows of a track without the parallax to triangulate (docs/algorithms.md
/// "Rotation rows"). The point is anchored in the track's last clone a in
/// inverse depth, each observation
///   z_i = π(R_iᵀ (R_a b + ρ (p_a − p_i))),   b = (α, β, 1),
/// and (α, β, ρ) fitted to the observations together with the depth prior
/// ρ ~ N(rho0, sigma_rho0²) (Gauss–Newton; sigma2_z: σ_z² of one whitened
/// row). The residuals are linearised there and projected on the left null
/// space of all three columns ∂z/∂(α, β, ρ): 2n − 3 rows. The ρ column is the
/// flow a translation gives the track, so what the depth's error does to
/// it is removed to first order; what remains constrains mostly the clones'
/// relative attitude, and their positions as a point at the fitted depth
/// would. No point is triangulated (out->p_W stays zero). kTooShort below
/// two observations.
MsckfOutcome rotationResidual(const FilterState& state, const FeatureTrack& track, MsckfResidual* out,
                              double sigma2_z, double rho0, double sigma_rho0);

}  // namespace evio::estimator

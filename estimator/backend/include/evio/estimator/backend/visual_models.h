#pragma once
/// @file visual_models.h
/// Camera measurement models of the backend and their Jacobians, with respect
/// to the error state of filter_state.h (clone error [δp_W_C; δθ_C] with
/// R_W_C = R̂ Exp(δθ_C); feature error [δα δβ δρ]).
///
/// Measurements are normalised image coordinates z = π(h) = (h_x/h_z, h_y/h_z)
/// of the undistorted observation (Mahlknecht et al. 2022, the feature measurement; docs/algorithms.md#visual-measurement-models).
///
///  - World point in clone i (MSCKF):      h = R_iᵀ (p_W − p_i)
///  - Anchored inverse depth (SLAM), anchor a, b = [α, β, 1]ᵀ:
///        h = R_iᵀ (R_a b + ρ (p_a − p_i))   (= ρ p_Ci, paper Eq. slam-coordinate-transform)
///    which stays well defined as ρ → 0 (a point at infinity).

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

using Mat26 = Eigen::Matrix<double, 2, 6>;
using Mat36 = Eigen::Matrix<double, 3, 6>;

/// Points closer to the image plane than this (h_z <= kMinDepthRatio · |h|)
/// are treated as not projectable.
inline constexpr double kMinDepthRatio = 1e-3;

/// The camera pose T_W_C = T_W_B T_B_C of an IMU state and its Jacobian with
/// respect to the IMU error state (15 columns, filter_state.h order):
///   δp_C = δp − R_W_B [p_B_C]x δθ,   δθ_C = R_C_B δθ   (R_W_C = R_W_B Exp(δθ) R_B_C).
Pose cameraPose(const ImuState& imu, const Pose& T_B_C, Eigen::Matrix<double, 6, 15>* d_cam_d_imu = nullptr);

/// Normalised projection of world point p_W into `clone`. Jacobians:
/// ∂z/∂[δp_W_C; δθ_C] (2×6) and ∂z/∂p_W (2×3). False when the point is not in
/// front of the camera (outputs unspecified).
bool projectWorldPoint(const CameraClone& clone, const Vec3& p_W, Vec2* z, Mat26* d_z_d_clone = nullptr,
                       Mat23* d_z_d_p_W = nullptr);

/// Normalised projection into `clone` of a feature anchored in `anchor` with
/// parameters abr = (α, β, ρ). Jacobians with respect to the anchor clone, the
/// observing clone and abr. When anchor and clone are the same clone, its total
/// Jacobian is the sum of the two (zero: z = (α, β) exactly). False when the
/// point is not in front of the camera.
bool projectAnchoredFeature(const CameraClone& anchor, const CameraClone& clone, const Vec3& abr, Vec2* z,
                            Mat26* d_z_d_anchor = nullptr, Mat26* d_z_d_clone = nullptr,
                            Mat23* d_z_d_abr = nullptr);

/// World point p_W = R_a [α, β, 1]ᵀ/ρ + p_a of an anchored feature (ρ ≠ 0),
/// with ∂p_W/∂[δp_a; δθ_a] and ∂p_W/∂abr.
Vec3 anchoredToWorld(const CameraClone& anchor, const Vec3& abr, Mat36* d_p_d_anchor = nullptr,
                     Mat3* d_p_d_abr = nullptr);

/// Anchored parameters (α, β, ρ) of world point p_W in `anchor` (the inverse
/// of anchoredToWorld). False when the point is not in front of the anchor.
bool worldToAnchored(const CameraClone& anchor, const Vec3& p_W, Vec3* abr);

/// Re-anchoring: the parameters of the same point anchored in `to` instead of
/// `from`:  h = R_toᵀ (R_from b + ρ (p_from − p_to)),  abr' = (h_x/h_z, h_y/h_z, ρ/h_z),
/// with Jacobians with respect to both clones and abr. False when the point is
/// not in front of `to`.
bool reanchorFeature(const CameraClone& from, const CameraClone& to, const Vec3& abr, Vec3* abr_new,
                     Mat36* d_new_d_from = nullptr, Mat36* d_new_d_to = nullptr, Mat3* d_new_d_abr = nullptr);

}  // namespace evio::estimator

#pragma once
/// @file range_update.h
/// Laser range-finder update (docs/algorithms.md#range-and-zero-velocity-updates, Mars-helicopter extension; the
/// xVIO range update): the beam from the range finder's origin o along its +z
/// axis d meets the terrain plane through three SLAM features q1, q2, q3
/// (those whose rays are nearest to the beam), and the predicted range is
///   n = (q2 − q1) × (q3 − q1),   range = nᵀ (q1 − o) / (nᵀ d),
///   o = p_W_B + R_W_B p_B_L,   d = R_W_B R_B_L e_z,
/// with q_k = anchoredToWorld(anchor_k, f_k). It fixes the scale in hover.

#include <optional>

#include "evio/core/eigen_types.h"
#include "evio/core/pose.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

/// Predicted range to the plane through q1, q2, q3 along the ray o + s d, with
/// Jacobians with respect to o, d and the three points (each 1×3). False when
/// the plane is (nearly) parallel to the beam or the triangle degenerate.
bool rangeToPlane(const Vec3& o, const Vec3& d, const Vec3& q1, const Vec3& q2, const Vec3& q3, double* range,
                  Eigen::Matrix<double, 1, 3>* d_r_d_o = nullptr, Eigen::Matrix<double, 1, 3>* d_r_d_d = nullptr,
                  Eigen::Matrix<double, 1, 9>* d_r_d_q = nullptr);

/// Depth-prior geometry of the range finder: the ray of normalised image
/// point z = (α, β) from `camera` (c + s R_W_C (α, β, 1), s > 0) meets the
/// level plane {x : x_z = plane_z_m} of W (z up) at
///   s = (plane_z_m − c_z) / (R_W_C (α, β, 1))_z,
/// which is the point's depth along the camera's z axis, so the anchored
/// inverse depth is ρ = 1/s. Nullopt when the ray points less than about 6°
/// below the horizon (|sin| < 0.1) or the depth is below min_depth_m.
std::optional<double> inverseDepthOnLevelPlane(const CameraClone& camera, const Vec2& z, double plane_z_m,
                                               double min_depth_m);

/// The range measurement of the state: residual r = measured − predicted and
/// H (1 × dim), using the three SLAM features whose rays (from the range
/// finder origin) are nearest to the beam, within max_angle_rad of it.
/// False when fewer than three such features exist or the plane is degenerate.
bool rangeResidual(const FilterState& state, const Pose& T_B_L, double measured_range_m, double max_angle_rad,
                   Eigen::Matrix<double, 1, Eigen::Dynamic>* H, double* r);

}  // namespace evio::estimator

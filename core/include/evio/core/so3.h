#pragma once
/// @file so3.h
/// SO(3) helpers on Eigen types: hat/vee, exponential and logarithm maps and
/// their right/left Jacobians. Conventions (Barfoot; Forster et al. 2017):
///   Exp(φ) = I + sin|φ|/|φ| [φ]x + (1-cos|φ|)/|φ|² [φ]x²
///   Exp(φ + δφ) ≈ Exp(φ) Exp(Jr(φ) δφ)           (right Jacobian)
///   Log(Exp(φ) Exp(δφ)) ≈ φ + Jr⁻¹(φ) δφ
///   Exp(φ + δφ) ≈ Exp(Jl(φ) δφ) Exp(φ),  Jl(φ) = Jr(-φ)

#include "evio/core/eigen_types.h"

namespace evio::so3 {

/// Skew-symmetric matrix [v]x with [v]x w = v × w.
Mat3 hat(const Vec3& v);

/// Inverse of hat for a skew-symmetric matrix.
Vec3 vee(const Mat3& m);

/// Rotation matrix Exp(φ), φ an axis-angle vector in rad.
Mat3 exp(const Vec3& phi);

/// Unit quaternion of Exp(φ).
Quat expQuat(const Vec3& phi);

/// Log(R): the axis-angle vector with |φ| <= π. Robust near 0 and π.
Vec3 log(const Mat3& R);

/// Log of a unit quaternion (shortest rotation, |φ| <= π).
Vec3 log(const Quat& q);

/// Right Jacobian Jr(φ).
Mat3 rightJacobian(const Vec3& phi);

/// Inverse of the right Jacobian, Jr⁻¹(φ).
Mat3 rightJacobianInverse(const Vec3& phi);

/// Left Jacobian Jl(φ) = Jr(-φ).
Mat3 leftJacobian(const Vec3& phi);

/// Inverse left Jacobian Jl⁻¹(φ) = Jr⁻¹(-φ).
Mat3 leftJacobianInverse(const Vec3& phi);

/// Nearest rotation matrix (SVD projection), to clean accumulated round-off.
Mat3 orthonormalize(const Mat3& R);

}  // namespace evio::so3

#pragma once
/// @file taylor_rotation.h
/// Rotation matrices as Taylor series in time (see taylor.h), and the
/// kinematic quantities they imply.
///
/// For R_W_B(t) with Ṙ = R [ω_B]x (ω_B: angular velocity of B relative to W,
/// expressed in B) and R̈ = R ([ω_B]x² + [α_B]x) (α_B = dω_B/dt):
///   [ω_B]x = Rᵀ Ṙ,   [α_B]x = skew part of Rᵀ R̈  ([ω]x² is symmetric).

#include "evio/core/so3.h"
#include "evio/trajectories/taylor.h"

namespace evio::taylor {

/// Rotation about a fixed unit axis n by a time-varying angle θ(t) (rad):
/// R = I + sin θ [n]x + (1 − cos θ) [n]x² (Rodrigues).
template <int N>
Matrix3<N> rotationAbout(const Vec3& unit_axis, const Scalar<N>& angle) {
  Scalar<N> s, c;
  sinCos(angle, &s, &c);
  const Mat3 K = so3::hat(unit_axis);
  const Mat3 K2 = K * K;
  Matrix3<N> R;
  for (int k = 0; k <= N; ++k) R.c[k] = s.c[k] * K - c.c[k] * K2;
  R.c[0] += Mat3::Identity() + K2;
  return R;
}

/// Exp(λ(t) φ) for a constant axis-angle vector φ (rad) and a scalar series λ.
template <int N>
Matrix3<N> expScaled(const Vec3& phi, const Scalar<N>& lambda) {
  const double theta = phi.norm();
  if (theta == 0.0) return Matrix3<N>::constant(Mat3::Identity());
  return rotationAbout<N>(phi / theta, theta * lambda);
}

/// R = Rz(yaw) Ry(pitch) Rx(roll): intrinsic z-y'-x'' Euler angles in rad
/// (yaw about W's z, then pitch, then roll about the body x axis).
template <int N>
Matrix3<N> eulerZYX(const Scalar<N>& yaw, const Scalar<N>& pitch, const Scalar<N>& roll) {
  return rotationAbout<N>(Vec3::UnitZ(), yaw) *
         (rotationAbout<N>(Vec3::UnitY(), pitch) * rotationAbout<N>(Vec3::UnitX(), roll));
}

/// Skew-symmetric part ½(M − Mᵀ) as a vector.
inline Vec3 veeOfSkewPart(const Mat3& m) { return so3::vee(0.5 * (m - m.transpose())); }

/// ω_B = vee(Rᵀ Ṙ) from a rotation series of order ≥ 1.
template <int N>
Vec3 angularVelocityBody(const Matrix3<N>& R) {
  static_assert(N >= 1, "needs the first derivative");
  return veeOfSkewPart(R.c[0].transpose() * R.c[1]);
}

/// α_B = vee(skew(Rᵀ R̈)) from a rotation series of order ≥ 2.
template <int N>
Vec3 angularAccelerationBody(const Matrix3<N>& R) {
  static_assert(N >= 2, "needs the second derivative");
  return veeOfSkewPart(R.c[0].transpose() * (2.0 * R.c[2]));
}

}  // namespace evio::taylor

#pragma once
/// @file pose.h
/// Rigid transforms. `Pose T_a_b` maps points from frame b into frame a:
/// p_a = T_a_b * p_b = R_a_b p_b + p_a_b. Composition reads left to right:
/// T_a_c = T_a_b * T_b_c.

#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/time.h"

namespace evio {

class Pose {
 public:
  Pose() = default;
  /// The quaternion is normalised unless it is already unit to round-off
  /// (so a pose read back from a file equals the one written, bit for bit).
  Pose(const Quat& q, const Vec3& p) : q_(unit(q)), p_(p) {}
  Pose(const Mat3& R, const Vec3& p) : q_(Quat(R).normalized()), p_(p) {}

  static Pose identity() { return Pose(); }

  const Quat& quaternion() const { return q_; }
  Mat3 rotation() const { return q_.toRotationMatrix(); }
  const Vec3& translation() const { return p_; }

  Pose inverse() const;
  Pose operator*(const Pose& other) const;
  Vec3 operator*(const Vec3& point) const { return q_ * point + p_; }
  Mat4 matrix() const;

  /// SE(3) exponential of ξ = [ρ; φ] (translation part first):
  /// T = [Exp(φ), Jl(φ) ρ; 0, 1].
  static Pose exp(const Vec6& xi);
  /// Inverse of exp: ξ = [Jl⁻¹(φ) p; φ] with φ = Log(R).
  Vec6 log() const;

 private:
  static Quat unit(const Quat& q) {
    const double n2 = q.squaredNorm();
    return (n2 > 1.0 - 4e-16 && n2 < 1.0 + 4e-16) ? q : q.normalized();
  }
  Quat q_ = Quat::Identity();
  Vec3 p_ = Vec3::Zero();
};

/// A pose at a time, e.g. one line of a TUM trajectory.
struct StampedPose {
  TimeNs t_ns = 0;
  Pose pose;  ///< T_W_X, X the frame the file states (event camera or IMU)
};

using Trajectory = std::vector<StampedPose>;

/// The pose at `t_ns` between two stamped poses (a.t_ns < b.t_ns; t_ns may lie
/// outside, which extrapolates): with s = (t − t_a) / (t_b − t_a), the
/// translation is (1 − s) p_a + s p_b and the rotation slerp(q_a, q_b, s).
/// Both poses are T_W_X of the same frames; so is the result. No shortcut at
/// the endpoints: s = 0 still goes through the slerp.
Pose interpolatePose(const StampedPose& a, const StampedPose& b, TimeNs t_ns);

/// The first pose of a time-sorted trajectory with t_ns >= `t_ns` (end() when
/// none), by binary search.
Trajectory::const_iterator firstPoseAtOrAfter(const Trajectory& trajectory, TimeNs t_ns);

/// Angle in rad of the rotation between two quaternions.
double angleBetween(const Quat& a, const Quat& b);

}  // namespace evio

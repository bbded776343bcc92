#include "evio/core/pose.h"

#include <algorithm>
#include <cmath>

#include "evio/core/so3.h"

namespace evio {

Pose Pose::inverse() const {
  const Quat q_inv = q_.conjugate();
  return Pose(q_inv, -(q_inv * p_));
}

Pose Pose::operator*(const Pose& other) const {
  return Pose(q_ * other.q_, q_ * other.p_ + p_);
}

Mat4 Pose::matrix() const {
  Mat4 m = Mat4::Identity();
  m.topLeftCorner<3, 3>() = rotation();
  m.topRightCorner<3, 1>() = p_;
  return m;
}

Pose Pose::exp(const Vec6& xi) {
  const Vec3 rho = xi.head<3>();
  const Vec3 phi = xi.tail<3>();
  return Pose(so3::expQuat(phi), so3::leftJacobian(phi) * rho);
}

Vec6 Pose::log() const {
  const Vec3 phi = so3::log(q_);
  Vec6 xi;
  xi.head<3>() = so3::leftJacobianInverse(phi) * p_;
  xi.tail<3>() = phi;
  return xi;
}

Pose interpolatePose(const StampedPose& a, const StampedPose& b, TimeNs t_ns) {
  const double s = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return Pose(a.pose.quaternion().slerp(s, b.pose.quaternion()),
              (1.0 - s) * a.pose.translation() + s * b.pose.translation());
}

Trajectory::const_iterator firstPoseAtOrAfter(const Trajectory& trajectory, TimeNs t_ns) {
  return std::lower_bound(trajectory.begin(), trajectory.end(), t_ns,
                          [](const StampedPose& p, TimeNs t) { return p.t_ns < t; });
}

double angleBetween(const Quat& a, const Quat& b) { return so3::log(a.conjugate() * b).norm(); }

}  // namespace evio

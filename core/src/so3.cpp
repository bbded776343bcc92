#include "evio/core/so3.h"

#include <Eigen/SVD>
#include <cmath>

namespace evio::so3 {
namespace {
constexpr double kSmallAngle = 1e-8;
}

Mat3 hat(const Vec3& v) {
  Mat3 m;
  m << 0.0, -v.z(), v.y(),  //
      v.z(), 0.0, -v.x(),   //
      -v.y(), v.x(), 0.0;
  return m;
}

Vec3 vee(const Mat3& m) { return Vec3(m(2, 1), m(0, 2), m(1, 0)); }

Mat3 exp(const Vec3& phi) { return expQuat(phi).toRotationMatrix(); }

Quat expQuat(const Vec3& phi) {
  const double theta = phi.norm();
  if (theta < kSmallAngle) {
    // q ≈ [1, φ/2], second order in θ.
    Quat q(1.0 - theta * theta / 8.0, 0.5 * phi.x(), 0.5 * phi.y(), 0.5 * phi.z());
    return q.normalized();
  }
  const double half = 0.5 * theta;
  const Vec3 axis = phi / theta;
  const double s = std::sin(half);
  return Quat(std::cos(half), s * axis.x(), s * axis.y(), s * axis.z());
}

Vec3 log(const Quat& q_in) {
  Quat q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation
  const Vec3 v = q.vec();
  const double s = v.norm();
  if (s < kSmallAngle) {
    // φ ≈ 2 v / w (first order; w ≈ 1).
    return 2.0 * v / q.w();
  }
  const double theta = 2.0 * std::atan2(s, q.w());  // in [0, π]
  return theta * v / s;
}

Vec3 log(const Mat3& R) { return log(Quat(R)); }

Mat3 rightJacobian(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = hat(phi);
  if (theta < 1e-5) return Mat3::Identity() - 0.5 * K + K * K / 6.0;
  const double t2 = theta * theta;
  return Mat3::Identity() - (1.0 - std::cos(theta)) / t2 * K +
         (theta - std::sin(theta)) / (t2 * theta) * K * K;
}

Mat3 rightJacobianInverse(const Vec3& phi) {
  const double theta = phi.norm();
  const Mat3 K = hat(phi);
  if (theta < 1e-5) return Mat3::Identity() + 0.5 * K + K * K / 12.0;
  const double t2 = theta * theta;
  const double coeff = 1.0 / t2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta));
  return Mat3::Identity() + 0.5 * K + coeff * K * K;
}

Mat3 leftJacobian(const Vec3& phi) { return rightJacobian(-phi); }

Mat3 leftJacobianInverse(const Vec3& phi) { return rightJacobianInverse(-phi); }

Mat3 orthonormalize(const Mat3& R) {
  Eigen::JacobiSVD<Mat3> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 out = svd.matrixU() * svd.matrixV().transpose();
  if (out.determinant() < 0.0) {
    Mat3 U = svd.matrixU();
    U.col(2) *= -1.0;
    out = U * svd.matrixV().transpose();
  }
  return out;
}

}  // namespace evio::so3

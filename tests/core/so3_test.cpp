#include "evio/core/so3.h"

#include <gtest/gtest.h>

#include "evio/core/pose.h"
#include "evio/core/random_stream.h"
#include "numeric_jacobian.h"

namespace evio {
namespace {

std::vector<Vec3> testAngles() {
  RandomStream rng(7, "so3_test");
  std::vector<Vec3> out = {Vec3::Zero(), Vec3(1e-9, 0, 0), Vec3(0, 1e-6, 2e-6), Vec3(0.3, -0.2, 0.1),
                           Vec3(0, 0, 3.0), Vec3(3.1, 0.05, 0)};
  for (int i = 0; i < 20; ++i) {
    Vec3 v(rng.normal(), rng.normal(), rng.normal());
    out.push_back(v.normalized() * rng.uniform(0.0, 3.1));
  }
  return out;
}

TEST(So3, HatIsCrossProduct) {
  const Vec3 a(1, -2, 3), b(0.5, 4, -1);
  EXPECT_TRUE((so3::hat(a) * b).isApprox(a.cross(b)));
  EXPECT_TRUE(so3::vee(so3::hat(a)).isApprox(a));
}

TEST(So3, ExpLogRoundTrip) {
  for (const auto& phi : testAngles()) {
    const Vec3 back = so3::log(so3::exp(phi));
    EXPECT_LT((back - phi).norm(), 1e-9) << phi.transpose();
  }
}

TEST(So3, ExpMatchesAngleAxis) {
  for (const auto& phi : testAngles()) {
    if (phi.norm() < 1e-12) continue;
    const Mat3 expected = Eigen::AngleAxisd(phi.norm(), phi.normalized()).toRotationMatrix();
    EXPECT_LT((so3::exp(phi) - expected).norm(), 1e-12);
  }
}

TEST(So3, LogNearPiIsStable) {
  const Vec3 axis = Vec3(1, 2, -1).normalized();
  const double pi = 3.14159265358979323846;
  for (double eps : {1e-3, 1e-6, 1e-9}) {
    const Vec3 phi = axis * (pi - eps);
    EXPECT_LT((so3::log(so3::exp(phi)) - phi).norm(), 1e-7);
  }
}

// Exp(φ + δ) ≈ Exp(φ) Exp(Jr(φ) δ): the numeric Jacobian of
// δ ↦ Log(Exp(φ)ᵀ Exp(φ + δ)) at δ = 0 is Jr(φ).
TEST(So3, RightJacobianMatchesNumeric) {
  for (const auto& phi : testAngles()) {
    const Mat3 R = so3::exp(phi);
    auto f = [&](const Vec3& d) -> Vec3 { return so3::log(Mat3(R.transpose() * so3::exp(phi + d))); };
    const Mat3 numeric = test::numericJacobian<3, 3>(f, Vec3::Zero());
    EXPECT_LT((numeric - so3::rightJacobian(phi)).norm(), 1e-7) << phi.transpose();
  }
}

// Log(Exp(φ) Exp(δ)) ≈ φ + Jr⁻¹(φ) δ.
TEST(So3, RightJacobianInverseMatchesNumeric) {
  for (const auto& phi : testAngles()) {
    if (phi.norm() > 3.0) continue;  // Log wraps near π; the inverse blows up there
    const Mat3 R = so3::exp(phi);
    auto f = [&](const Vec3& d) -> Vec3 { return so3::log(Mat3(R * so3::exp(d))); };
    const Mat3 numeric = test::numericJacobian<3, 3>(f, Vec3::Zero());
    EXPECT_LT((numeric - so3::rightJacobianInverse(phi)).norm(), 1e-6) << phi.transpose();
    EXPECT_LT((so3::rightJacobianInverse(phi) * so3::rightJacobian(phi) - Mat3::Identity()).norm(),
              1e-9);
  }
}

// Exp(φ + δ) ≈ Exp(Jl(φ) δ) Exp(φ).
TEST(So3, LeftJacobianMatchesNumeric) {
  for (const auto& phi : testAngles()) {
    const Mat3 R = so3::exp(phi);
    auto f = [&](const Vec3& d) -> Vec3 { return so3::log(Mat3(so3::exp(phi + d) * R.transpose())); };
    const Mat3 numeric = test::numericJacobian<3, 3>(f, Vec3::Zero());
    EXPECT_LT((numeric - so3::leftJacobian(phi)).norm(), 1e-7);
  }
}

TEST(Se3, ExpLogRoundTripAndComposition) {
  RandomStream rng(11, "se3_test");
  for (int i = 0; i < 50; ++i) {
    Vec6 xi;
    for (int k = 0; k < 6; ++k) xi(k) = rng.normal();
    xi.tail<3>() = xi.tail<3>().normalized() * rng.uniform(0.0, 3.0);
    const Pose T = Pose::exp(xi);
    EXPECT_LT((T.log() - xi).norm(), 1e-9);
    const Pose I = T * T.inverse();
    EXPECT_LT(I.translation().norm(), 1e-12);
    EXPECT_LT(angleBetween(I.quaternion(), Quat::Identity()), 1e-12);
    const Vec3 p(rng.normal(), rng.normal(), rng.normal());
    EXPECT_TRUE((T * p).isApprox(T.rotation() * p + T.translation()));
    EXPECT_TRUE((T.matrix() * p.homogeneous()).head<3>().isApprox(T * p));
  }
}

}  // namespace
}  // namespace evio

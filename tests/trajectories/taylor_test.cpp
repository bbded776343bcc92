#include "evio/trajectories/taylor.h"

#include <gtest/gtest.h>

#include <cmath>

#include "evio/trajectories/motion_primitives.h"
#include "evio/trajectories/taylor_rotation.h"

namespace evio {
namespace {

using taylor::Scalar;

// Exact derivatives of closed forms, compared to the series' coefficients.
// Tolerances are a few ulps of the magnitudes involved.

TEST(Taylor, ProductQuotientAndChainRuleMatchClosedForms) {
  const double t0 = 0.7;
  const Scalar<4> t = taylor::variable<4>(t0);
  // f = sin(t²): f' = 2t cos t², f'' = 2 cos t² − 4t² sin t²,
  // f''' = −12 t sin t² − 8 t³ cos t².
  const Scalar<4> f = taylor::sin(t * t);
  const double x = t0 * t0;
  EXPECT_NEAR(f.derivative(0), std::sin(x), 1e-15);
  EXPECT_NEAR(f.derivative(1), 2 * t0 * std::cos(x), 1e-14);
  EXPECT_NEAR(f.derivative(2), 2 * std::cos(x) - 4 * x * std::sin(x), 1e-14);
  EXPECT_NEAR(f.derivative(3), -12 * t0 * std::sin(x) - 8 * t0 * x * std::cos(x), 1e-13);

  // g = 1 / (1 + t²): g' = −2t/(1+t²)², g'' = (6t² − 2)/(1+t²)³.
  const Scalar<4> g = Scalar<4>::constant(1.0) / (t * t + 1.0);
  const double d = 1 + x;
  EXPECT_NEAR(g.derivative(1), -2 * t0 / (d * d), 1e-15);
  EXPECT_NEAR(g.derivative(2), (6 * x - 2) / (d * d * d), 1e-14);

  // h = sqrt(1 + t²): h' = t/h, h'' = 1/h³.
  const Scalar<4> h = taylor::sqrt(t * t + 1.0);
  EXPECT_NEAR(h.derivative(1), t0 / std::sqrt(d), 1e-15);
  EXPECT_NEAR(h.derivative(2), 1.0 / std::pow(d, 1.5), 1e-15);

  // Differentiating the series of f gives the series of f'.
  const Scalar<3> df = taylor::differentiate<1>(f);
  EXPECT_NEAR(df.derivative(2), f.derivative(3), 1e-13);
  EXPECT_EQ(taylor::truncate<2>(f).c[2], f.c[2]);
}

TEST(Taylor, SmoothStepIsFlatAtItsEndsAndExactInside) {
  // S = f(u)/(f(u) + f(1−u)), f = exp(−1/x): S(½) = ½, S'(½) = 2 (logistic of
  // 1/(1−u) − 1/u, whose slope at ½ is 8, times ¼), S''(½) = 0 by symmetry.
  const Scalar<4> mid = motion::smoothStep(taylor::variable<4>(0.5));
  EXPECT_NEAR(mid.derivative(0), 0.5, 1e-15);
  EXPECT_NEAR(mid.derivative(1), 2.0, 1e-14);
  EXPECT_NEAR(mid.derivative(2), 0.0, 1e-13);
  // S'(u) closed form at u = 0.3: S' = S(1−S)(1/u² + 1/(1−u)²).
  const double u = 0.3;
  const double S = 1.0 / (1.0 + std::exp(1.0 / u - 1.0 / (1.0 - u)));
  const Scalar<4> s3 = motion::smoothStep(taylor::variable<4>(u));
  EXPECT_NEAR(s3.derivative(0), S, 1e-15);
  EXPECT_NEAR(s3.derivative(1), S * (1 - S) * (1 / (u * u) + 1 / ((1 - u) * (1 - u))), 1e-14);
  // Every derivative is vanishingly small near the ends (f(0.01) = e⁻¹⁰⁰).
  for (const double e : {0.01, 0.99}) {
    const Scalar<4> s = motion::smoothStep(taylor::variable<4>(e));
    for (int k = 1; k <= 4; ++k) EXPECT_LT(std::abs(s.derivative(k)), 1e-20) << "u=" << e << " k=" << k;
  }
  EXPECT_EQ(motion::smoothStep(taylor::variable<4>(-1.0)).derivative(0), 0.0);
  EXPECT_EQ(motion::smoothStep(taylor::variable<4>(2.0)).derivative(0), 1.0);
  EXPECT_EQ(motion::smoothStep(taylor::variable<4>(1e-5)).derivative(1), 0.0);
}

TEST(Taylor, SmoothStepPeakSecondDerivativeIsTheStatedConstant) {
  // The exact series' S'' on a 1e-5 grid: its maximum is the constant (found
  // to 40 digits with mpmath), at u ≈ 0.21826, and −S'' mirrors it at 1 − u.
  double peak = 0.0, at = 0.0;
  for (int i = 1; i < 100000; ++i) {
    const double u = i * 1e-5;
    const double s2 = motion::smoothStep(taylor::variable<2>(u)).derivative(2);
    if (std::abs(s2) > peak) peak = std::abs(s2), at = u;
  }
  EXPECT_LE(peak, motion::kSmoothStepPeakSecondDerivative * (1 + 1e-12));
  EXPECT_NEAR(peak, motion::kSmoothStepPeakSecondDerivative, 1e-7);  // grid within 1e-5 of the peak: ΔS'' ~ S''''·Δu²/2
  EXPECT_TRUE(std::abs(at - 0.21826) < 2e-5 || std::abs(at - (1 - 0.21826)) < 2e-5) << at;
}

TEST(Taylor, EulerRatesGiveTheKnownBodyAngularVelocity) {
  // For R = Rz(ψ) Ry(θ) Rx(φ):
  //   ω_B = [φ̇ − ψ̇ sin θ,  θ̇ cos φ + ψ̇ cos θ sin φ,  −θ̇ sin φ + ψ̇ cos θ cos φ].
  const double t0 = 0.3;
  const Scalar<2> t = taylor::variable<2>(t0);
  const Scalar<2> yaw = 0.8 * taylor::sin(2.0 * t);
  const Scalar<2> pitch = 0.4 * taylor::cos(3.0 * t);
  const Scalar<2> roll = 0.5 * t * t;
  const taylor::Matrix3<2> R = taylor::eulerZYX(yaw, pitch, roll);
  const double th = pitch.c[0], ph = roll.c[0];
  const double dps = yaw.derivative(1), dth = pitch.derivative(1), dph = roll.derivative(1);
  const Vec3 omega(dph - dps * std::sin(th), dth * std::cos(ph) + dps * std::cos(th) * std::sin(ph),
                   -dth * std::sin(ph) + dps * std::cos(th) * std::cos(ph));
  EXPECT_LT((taylor::angularVelocityBody(R) - omega).norm(), 1e-14);
  // The value is a rotation.
  EXPECT_LT((R.c[0].transpose() * R.c[0] - Mat3::Identity()).norm(), 1e-15);
}

TEST(Taylor, RotationAboutAFixedAxisHasConstantAxisRates) {
  // Exp(λ(t) φ): ω_B = λ̇ φ, α_B = λ̈ φ exactly.
  const Vec3 phi(0.3, -0.2, 0.9);
  const Scalar<2> t = taylor::variable<2>(1.1);
  const Scalar<2> lambda = taylor::sin(t) + 0.2 * t * t;
  const taylor::Matrix3<2> R = taylor::expScaled(phi, lambda);
  EXPECT_LT((taylor::angularVelocityBody(R) - lambda.derivative(1) * phi).norm(), 1e-15);
  EXPECT_LT((taylor::angularAccelerationBody(R) - lambda.derivative(2) * phi).norm(), 1e-15);
  EXPECT_LT((R.c[0] - so3::exp(lambda.c[0] * phi)).norm(), 1e-15);
}

TEST(Taylor, VectorOperationsFollowTheProductRule) {
  const Scalar<2> t = taylor::variable<2>(0.4);
  const taylor::Vector3<2> a = taylor::makeVector(taylor::cos(t), taylor::sin(t), t);
  const taylor::Vector3<2> b = taylor::makeVector(t * t, Scalar<2>::constant(1.0), -1.0 * t);
  // d/dt (a × b) = ȧ × b + a × ḃ;  d/dt (a·b) = ȧ·b + a·ḃ.
  const Vec3 a0 = a.c[0], a1 = a.derivative(1), b0 = b.c[0], b1 = b.derivative(1);
  EXPECT_LT((taylor::cross(a, b).derivative(1) - (a1.cross(b0) + a0.cross(b1))).norm(), 1e-15);
  EXPECT_NEAR(taylor::dot(a, b).derivative(1), a1.dot(b0) + a0.dot(b1), 1e-15);
  const taylor::Vector3<2> n = taylor::normalized(a);
  EXPECT_NEAR(n.c[0].norm(), 1.0, 1e-15);
  EXPECT_NEAR(n.c[0].dot(n.derivative(1)), 0.0, 1e-15);  // unit vectors move tangentially
}

}  // namespace
}  // namespace evio

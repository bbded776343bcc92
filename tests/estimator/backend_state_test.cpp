// Backend Jacobians over the whole error state (filter_state.h convention),
// the IMU transition, clone augmentation and the χ² quantiles.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "evio/core/error.h"

#include "evio/core/random_stream.h"
#include "random_state.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/imu_propagation.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/visual_models.h"
#include "numeric_jacobian.h"
#include "numeric_state_jacobian.h"

namespace evio::estimator {
namespace {

using test::numericStateJacobian;
using test::randomSpdCovariance;
using test::randomVec3;

// A downward-looking helicopter state with 4 clones and 4 SLAM features on
// the ground below, and a random SPD covariance.
FilterState makeState(std::uint64_t seed) {
  RandomStream rng(seed, "state");
  FilterState s;
  s.imu.p_W_B = Vec3(0.2, -0.1, 10.0) + randomVec3(rng, 0.1);
  s.imu.v_W = randomVec3(rng, 0.5);
  s.imu.q_W_B = so3::expQuat(randomVec3(rng, 0.1));
  s.imu.b_g = randomVec3(rng, 0.01);
  s.imu.b_a = randomVec3(rng, 0.1);
  const Mat3 R_down = Vec3(1.0, -1.0, -1.0).asDiagonal();  // camera z along −z of W
  for (int i = 0; i < 4; ++i) {
    CameraClone c;
    c.id = 10 + i;
    c.p_W_C = Vec3(0.3 * i, 0.1 * i, 10.0) + randomVec3(rng, 0.05);
    c.q_W_C = Quat(R_down * so3::exp(randomVec3(rng, 0.05)));
    s.clones.push_back(c);
  }
  const Vec3 ground[4] = {Vec3(1.0, 1.0, 0.3), Vec3(-1.5, 0.5, -0.2), Vec3(0.5, -2.0, 0.1), Vec3(0.2, 0.3, 0.0)};
  for (int j = 0; j < 4; ++j) {
    SlamFeature f;
    f.id = 100 + j;
    f.anchor_clone_id = 10 + j % 3;
    EXPECT_TRUE(worldToAnchored(s.clones[static_cast<std::size_t>(j % 3)], ground[j], &f.abr));
    s.features.push_back(f);
  }
  s.P = randomSpdCovariance(s.dim(), 1e-3, rng);
  return s;
}

TEST(BackendStateJacobians, SlamResidualOverTheWholeState) {
  const FilterState s = makeState(1);
  for (std::size_t j = 0; j < s.features.size(); ++j) {
    for (std::size_t c : {std::size_t{0}, std::size_t{3}}) {  // includes the anchor itself for j = 0
      Eigen::Matrix<double, 2, Eigen::Dynamic> H;
      Vec2 r;
      const Vec2 z(0.01, -0.02);
      ASSERT_TRUE(slamResidual(s, j, c, z, &H, &r));
      // r = z − h(x): ∂r/∂δx = −H ⇒ H = −∂r/∂δx.
      const MatX num = numericStateJacobian(
          s,
          [&](const FilterState& x) {
            Eigen::Matrix<double, 2, Eigen::Dynamic> Hx;
            Vec2 rr;
            EXPECT_TRUE(slamResidual(x, j, c, z, &Hx, &rr));
            return VecX(-rr);
          },
          2);
      EXPECT_LT((MatX(H) - num).norm(), 1e-7) << "feature " << j << " clone " << c;
    }
  }
}

// The second-order term of a SLAM observation (slamSecondOrderCovariance) is
// what the linearisation leaves out: errors drawn in the clones' positions and
// the inverse depth only (rotations exact), the remainder
// h(x ⊞ δx) − h(x) − H δx has, over 200 000 draws, the stated covariance
// within 3 % (Frobenius; sampling error about 1 %, the projection's own
// curvature well below that at σ_ρ = 0.5 ρ and 3 cm between the clones).
TEST(BackendStateJacobians, SlamSecondOrderCovarianceIsTheLinearisationRemainder) {
  FilterState s = makeState(3);
  const std::size_t j = 1, c = 3;  // feature 1 is anchored in clone 1
  const int a = s.findClone(s.features[j].anchor_clone_id);
  ASSERT_GE(a, 0);
  const int rho = s.featureIndex(j) + 2;
  const int pa = s.cloneIndex(static_cast<std::size_t>(a)) + kCloneP, pc = s.cloneIndex(c) + kCloneP;
  // δ = (δp_a, δp_c, δρ): σ_p 3 cm, σ_ρ half of ρ, δρ correlated with δp_c.
  Eigen::Matrix<double, 7, 7> C = Eigen::Matrix<double, 7, 7>::Zero();
  C.topLeftCorner<6, 6>() = 9e-4 * Eigen::Matrix<double, 6, 6>::Identity();
  const double sigma_rho = 0.5 * s.features[j].abr.z();
  C(6, 6) = sigma_rho * sigma_rho;
  C(3, 6) = C(6, 3) = 0.5 * 0.03 * sigma_rho;
  const int idx[7] = {pa, pa + 1, pa + 2, pc, pc + 1, pc + 2, rho};
  s.P.setZero();
  for (int r = 0; r < 7; ++r)
    for (int q = 0; q < 7; ++q) s.P(idx[r], idx[q]) = C(r, q);
  Mat2 stated;
  ASSERT_TRUE(slamSecondOrderCovariance(s, j, c, &stated));

  const Vec2 z = Vec2::Zero();
  Eigen::Matrix<double, 2, Eigen::Dynamic> H;
  Vec2 r0;
  ASSERT_TRUE(slamResidual(s, j, c, z, &H, &r0));
  const Eigen::Matrix<double, 7, 7> L = C.llt().matrixL();
  RandomStream rng(4, "second_order");
  constexpr int kDraws = 200000;
  Vec2 mean = Vec2::Zero();
  Mat2 second = Mat2::Zero();
  for (int k = 0; k < kDraws; ++k) {
    Eigen::Matrix<double, 7, 1> n;
    for (int i = 0; i < 7; ++i) n(i) = rng.normal();
    const Eigen::Matrix<double, 7, 1> d7 = L * n;
    VecX dx = VecX::Zero(s.dim());
    for (int i = 0; i < 7; ++i) dx(idx[i]) = d7(i);
    FilterState x = s;
    x.correct(dx);
    Eigen::Matrix<double, 2, Eigen::Dynamic> Hx;
    Vec2 r;
    ASSERT_TRUE(slamResidual(x, j, c, z, &Hx, &r));
    const Vec2 remainder = (r0 - r) - H * dx;  // h(x ⊞ δx) − h(x) − H δx, with h = z − r
    mean += remainder / kDraws;
    second += remainder * remainder.transpose() / kDraws;
  }
  const Mat2 measured = second - mean * mean.transpose();
  EXPECT_GT(stated.trace(), 1e-7);  // a pixel's order at f = 200 px is 2.5e-5
  EXPECT_LT((measured - stated).norm(), 0.03 * stated.norm()) << "stated\n" << stated << "\nmeasured\n" << measured;

  // In the anchor itself the term vanishes: h = R_aᵀ R_a b does not depend on ρ.
  ASSERT_TRUE(slamSecondOrderCovariance(s, j, static_cast<std::size_t>(a), &stated));
  EXPECT_LT(stated.norm(), 1e-15);
}

TEST(BackendStateJacobians, WhiteningWithExtraCovarianceWhitensTheSum) {
  const Mat2 W = (Mat2() << 2.0, 0.0, 0.5, 1.5).finished();
  const Mat2 extra = (Mat2() << 3e-4, 1e-4, 1e-4, 2e-4).finished();
  const double sigma_z = 0.01;
  const Mat2 W_inv = W.inverse();
  const Mat2 cov = sigma_z * sigma_z * W_inv * W_inv.transpose() + extra;
  const Mat2 Wn = whitenWithExtraCovariance(W, sigma_z, extra);
  EXPECT_LT((Wn * cov * Wn.transpose() - sigma_z * sigma_z * Mat2::Identity()).norm(), 1e-15);
  EXPECT_LT((whitenWithExtraCovariance(W, sigma_z, Mat2::Zero()) * (sigma_z * sigma_z * W_inv * W_inv.transpose()) *
                 whitenWithExtraCovariance(W, sigma_z, Mat2::Zero()).transpose() -
             sigma_z * sigma_z * Mat2::Identity())
                .norm(),
            1e-15);
}

TEST(BackendStateJacobians, RangeResidualOverTheWholeState) {
  const FilterState s = makeState(2);
  const Pose T_B_L(so3::expQuat(Vec3(M_PI, 0.0, 0.0)), Vec3(0.05, 0.0, -0.1));  // beam along −z of B
  Eigen::Matrix<double, 1, Eigen::Dynamic> H;
  double r = 0.0;
  ASSERT_TRUE(rangeResidual(s, T_B_L, 10.0, 60.0 * M_PI / 180.0, &H, &r));
  const MatX num = numericStateJacobian(
      s,
      [&](const FilterState& x) {
        Eigen::Matrix<double, 1, Eigen::Dynamic> Hx;
        double rr = 0.0;
        EXPECT_TRUE(rangeResidual(x, T_B_L, 10.0, 60.0 * M_PI / 180.0, &Hx, &rr));
        return VecX::Constant(1, -rr);
      },
      1);
  EXPECT_LT((MatX(H) - num).norm(), 1e-6);
  // Fewer than three features near the beam: no update.
  EXPECT_FALSE(rangeResidual(s, T_B_L, 10.0, 1e-4, &H, &r));
}

// Error between two IMU states in the filter convention.
Eigen::Matrix<double, 15, 1> imuError(const ImuState& x, const ImuState& ref) {
  Eigen::Matrix<double, 15, 1> e;
  e.segment<3>(kIdxP) = x.p_W_B - ref.p_W_B;
  e.segment<3>(kIdxV) = x.v_W - ref.v_W;
  e.segment<3>(kIdxTheta) = so3::log(Quat(ref.q_W_B.conjugate() * x.q_W_B));
  e.segment<3>(kIdxBg) = x.b_g - ref.b_g;
  e.segment<3>(kIdxBa) = x.b_a - ref.b_a;
  return e;
}

ImuState boxPlus(const ImuState& x, const Eigen::Matrix<double, 15, 1>& d) {
  ImuState y = x;
  y.p_W_B += d.segment<3>(kIdxP);
  y.v_W += d.segment<3>(kIdxV);
  y.q_W_B = x.q_W_B * so3::expQuat(d.segment<3>(kIdxTheta));
  y.b_g += d.segment<3>(kIdxBg);
  y.b_a += d.segment<3>(kIdxBa);
  return y;
}

TEST(BackendStateJacobians, ImuTransitionIsTheJacobianOfTheIntegrator) {
  RandomStream rng(3, "imu");
  ImuState x;
  x.p_W_B = randomVec3(rng, 1.0);
  x.v_W = randomVec3(rng, 1.0);
  x.q_W_B = so3::expQuat(randomVec3(rng, 1.0));
  x.b_g = randomVec3(rng, 0.05);
  x.b_a = randomVec3(rng, 0.2);
  ImuSample s0, s1;
  s0.t_ns = 0;
  s1.t_ns = 5'000'000;  // a long 5 ms step, so the higher-order terms matter
  s0.acc_B = Vec3(0.5, -1.0, 9.6);
  s1.acc_B = Vec3(1.5, -0.2, 10.4);
  s0.gyro_B = Vec3(1.0, -2.0, 0.5);
  s1.gyro_B = Vec3(2.5, -1.0, -0.5);
  const Vec3 g(0, 0, -9.81);
  ImuState nominal = x;
  Mat15 Phi;
  integrateImuStep(nominal, s0, s1, g, &Phi);
  using Vec15 = Eigen::Matrix<double, 15, 1>;
  const auto f = [&](const Vec15& d) {
    ImuState y = boxPlus(x, d);
    integrateImuStep(y, s0, s1, g);
    return Vec15(imuError(y, nominal));
  };
  EXPECT_LT((Phi - test::numericJacobian<15, 15>(f, Vec15::Zero())).norm(), 1e-7);
}

TEST(BackendStateJacobians, CameraPoseOfTheImuState) {
  RandomStream rng(5, "camera");
  ImuState x;
  x.p_W_B = randomVec3(rng, 1.0);
  x.q_W_B = so3::expQuat(randomVec3(rng, 1.0));
  const Pose T_B_C(so3::expQuat(Vec3(1.2, -0.3, 0.4)), Vec3(0.05, -0.02, 0.1));
  Eigen::Matrix<double, 6, 15> J;
  const Pose T_W_C = cameraPose(x, T_B_C, &J);
  EXPECT_LT((T_W_C.matrix() - (x.T_W_B() * T_B_C).matrix()).norm(), 1e-15);
  using Vec15 = Eigen::Matrix<double, 15, 1>;
  const auto f = [&](const Vec15& d) {
    const Pose T = cameraPose(boxPlus(x, d), T_B_C);
    Vec6 e;
    e.head<3>() = T.translation() - T_W_C.translation();
    e.tail<3>() = so3::log(Quat(T_W_C.quaternion().conjugate() * T.quaternion()));
    return e;
  };
  EXPECT_LT((J - test::numericJacobian<6, 15>(f, Vec15::Zero())).norm(), 1e-8);
}

TEST(BackendStateJacobians, DiscreteNoiseIsSymmetricPositiveDefinite) {
  ImuNoiseDensities n{0.004316, 0.0004316, 0.0002, 0.00002};
  const Mat15 Q = discreteImuNoise(so3::exp(Vec3(0.3, -0.2, 1.0)), Vec3(1.0, 2.0, 9.0), 0.005, n);
  EXPECT_LT((Q - Q.transpose()).norm(), 1e-20);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Mat15>(Q).eigenvalues().minCoeff(), 0.0);
  // Leading terms: σ_g² Δt (attitude), σ_a² Δt (velocity), σ_b² Δt (biases).
  EXPECT_NEAR(Q(kIdxTheta, kIdxTheta), 0.0002 * 0.0002 * 0.005, 1e-14);
  EXPECT_NEAR(Q(kIdxV, kIdxV) / (0.004316 * 0.004316 * 0.005), 1.0, 1e-3);
  EXPECT_NEAR(Q(kIdxBa, kIdxBa), 0.0004316 * 0.0004316 * 0.005, 1e-18);
}

TEST(BackendStateJacobians, RegularizedGammaAndChiSquaredQuantiles) {
  // Reference values (mpmath regularised incomplete gamma, 30 digits, rounded).
  EXPECT_NEAR(chi2Quantile(0.95, 1), 3.841458821, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.95, 2), 5.991464547, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.95, 10), 18.30703805, 1e-7);
  EXPECT_NEAR(chi2Quantile(0.05, 10), 3.940299136, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.99, 3), 11.34486673, 1e-7);
  EXPECT_NEAR(chi2Quantile(0.025, 300), 253.91232260249, 1e-8);
  EXPECT_NEAR(chi2Quantile(0.975, 300), 349.874468829915, 1e-8);
  // χ²(2) has the closed-form CDF 1 − e^{−x/2}.
  for (double x : {0.1, 1.0, 4.0, 20.0}) EXPECT_NEAR(chi2Cdf(x, 2), 1.0 - std::exp(-x / 2), 1e-14);
  for (int k : {1, 3, 7, 50, 400})
    for (double p : {0.01, 0.5, 0.95, 0.999}) EXPECT_NEAR(chi2Cdf(chi2Quantile(p, k), k), p, 1e-12);
  const Chi2Table table(0.95);
  EXPECT_DOUBLE_EQ(table(2), chi2Quantile(0.95, 2));
  EXPECT_THROW(chi2Quantile(1.0, 2), Error);
  EXPECT_THROW(chi2Quantile(0.5, 0), Error);
}

}  // namespace
}  // namespace evio::estimator

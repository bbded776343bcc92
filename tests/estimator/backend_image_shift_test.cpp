// The image shift the features share (filter_state.h, has_image_shift): its
// place in the error-state layout beside features and the scene depth, the
// SLAM residual's Jacobian over it (only for the newest clone's
// observations), and its Gauss–Markov step.
#include <gtest/gtest.h>

#include <cmath>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"
#include "evio/estimator/backend/slam_features.h"
#include "down_looking_state.h"
#include "numeric_state_jacobian.h"
#include "random_state.h"

namespace evio::estimator {
namespace {

using test::numericStateJacobian;
using test::randomSpdCovariance;

const Mat2 kShiftCov = Vec2(4e-6, 9e-6).asDiagonal();  // normalised units²
constexpr double kShiftTime_s = 0.05;

// Three clones looking down from 10 m, the image shift added before two
// features (which then go in front of it), a nonzero shift and a random SPD
// covariance.
FilterState makeStateWithShift(std::uint64_t seed) {
  RandomStream rng(seed, "image_shift_state");
  FilterState s;
  test::addDownLookingClones(s, rng);
  s.addImageShift(kShiftCov, kShiftTime_s);
  EXPECT_TRUE(test::addTwoGroundFeatures(s));
  s.image_shift = Vec2(rng.normal(), rng.normal()) * 0.002;
  s.P = randomSpdCovariance(s.dim(), 1e-3, rng);
  return s;
}

TEST(ImageShiftState, SitsAfterTheFeaturesAndBeforeTheSceneDepth) {
  FilterState s = makeStateWithShift(1);
  EXPECT_EQ(s.dim(), kImuDim + 3 * kCloneDim + 2 * kFeatureDim + kImageShiftDim);
  EXPECT_EQ(s.imageShiftIndex(), s.featureIndex(2));
  s.addSceneDepth(0.5, 0.01);
  EXPECT_EQ(s.sceneDepthIndex(), s.imageShiftIndex() + kImageShiftDim);
  EXPECT_EQ(s.sceneDepthIndex(), s.dim() - 1);
  // A feature added now goes before both, and the shift's block moves with it.
  const Mat2 P_ss = s.P.block<2, 2>(s.imageShiftIndex(), s.imageShiftIndex());
  SlamFeature f;
  f.id = 300;
  f.anchor_clone_id = 12;
  f.abr = Vec3(0.1, 0.2, 0.5);
  s.addFeature(f, Mat3::Identity() * 1e-4, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, s.dim()));
  EXPECT_EQ(s.imageShiftIndex(), s.featureIndex(3));
  EXPECT_EQ(Mat2(s.P.block<2, 2>(s.imageShiftIndex(), s.imageShiftIndex())), P_ss);
  // correct() and minus() carry the shift: x ⊟ ref undoes correct().
  const FilterState ref = s;
  VecX dx = VecX::Zero(s.dim());
  dx.segment<2>(s.imageShiftIndex()) = Vec2(1e-3, -2e-3);
  dx(s.sceneDepthIndex()) = 0.02;
  s.correct(dx);
  EXPECT_LT((s.image_shift - ref.image_shift - Vec2(1e-3, -2e-3)).norm(), 1e-15);
  EXPECT_LT((s.minus(ref) - dx).norm(), 1e-12);
  // Only one shift.
  EXPECT_THROW(s.addImageShift(kShiftCov, kShiftTime_s), Error);
}

TEST(ImageShiftState, NewlyAddedShiftIsUncorrelatedWithTheRest) {
  FilterState s;
  s.P = MatX::Identity(kImuDim, kImuDim) * 0.1;
  s.addImageShift(kShiftCov, kShiftTime_s);
  ASSERT_EQ(s.dim(), kImuDim + kImageShiftDim);
  EXPECT_EQ(Mat2(s.P.block<2, 2>(kImuDim, kImuDim)), kShiftCov);
  EXPECT_EQ(s.P.block(kImuDim, 0, 2, kImuDim).norm(), 0.0);
  EXPECT_EQ(s.image_shift, Vec2::Zero());
  FilterState bad;
  bad.P = MatX::Identity(kImuDim, kImuDim);
  EXPECT_THROW(bad.addImageShift(Mat2::Zero(), kShiftTime_s), Error);
  EXPECT_THROW(bad.addImageShift(kShiftCov, 0.0), Error);
}

// r = z − π(h) − s in the newest clone: H = −∂r/∂δx by central differences
// over correct(), the shift's block the identity; in an older clone the
// shift does not enter.
TEST(ImageShiftState, SlamResidualJacobianCoversTheShiftInTheNewestCloneOnly) {
  const FilterState s = makeStateWithShift(2);
  const Vec2 z(0.01, -0.02);
  for (const std::size_t c : {std::size_t{2}, std::size_t{1}}) {
    for (std::size_t j = 0; j < s.features.size(); ++j) {
      Eigen::Matrix<double, 2, Eigen::Dynamic> H;
      Vec2 r;
      ASSERT_TRUE(slamResidual(s, j, c, z, &H, &r));
      const MatX num = numericStateJacobian(
          s,
          [&](const FilterState& x) {
            Eigen::Matrix<double, 2, Eigen::Dynamic> Hx;
            Vec2 rx;
            EXPECT_TRUE(slamResidual(x, j, c, z, &Hx, &rx));
            return VecX(-rx);
          },
          2);
      EXPECT_LT((MatX(H) - num).norm(), 1e-7) << "clone " << c << " feature " << j;
      const MatX H_s = H.block(0, s.imageShiftIndex(), 2, 2);
      if (c == 2)
        EXPECT_TRUE(H_s.isApprox(MatX::Identity(2, 2))) << "feature " << j;
      else
        EXPECT_EQ(H_s.norm(), 0.0) << "feature " << j;
    }
  }
  // The shift moves the newest clone's residual by exactly −s.
  FilterState zero = s;
  zero.image_shift.setZero();
  Eigen::Matrix<double, 2, Eigen::Dynamic> H;
  Vec2 r, r0;
  ASSERT_TRUE(slamResidual(s, 0, 2, z, &H, &r));
  ASSERT_TRUE(slamResidual(zero, 0, 2, z, &H, &r0));
  EXPECT_LT((r - (r0 - s.image_shift)).norm(), 1e-15);
}

// A bearing from an observation of the newest clone, z = b + s + n: b̂ = z − ŝ,
// δb = −δs − n, so Cov(δb) = Σ_n + P_ss, Cov(δb, δx) = −P_sx for every other
// entry x. From an older clone the shift plays no part.
TEST(ImageShiftState, NewFeatureBearingCarriesMinusTheShift) {
  FilterState s = makeStateWithShift(6);
  const FilterState before = s;
  const Vec2 z(0.05, -0.04);
  const double sigma_z = 0.004, sigma_rho0 = 0.5;
  addSlamFeatureWithPrior(s, 400, 2, z, 1.0, sigma_rho0, sigma_z);
  ASSERT_EQ(s.dim(), before.dim() + kFeatureDim);
  // The new feature takes the shift's old place (a == k0) and the shift moves behind it.
  const int a = s.featureIndex(2), k = s.imageShiftIndex(), k0 = before.imageShiftIndex();
  EXPECT_LT((s.features[2].abr.head<2>() - (z - before.image_shift)).norm(), 1e-15);
  const Mat2 P_ss = before.P.block<2, 2>(k0, k0);
  EXPECT_LT((Mat2(s.P.block<2, 2>(a, a)) - (sigma_z * sigma_z * Mat2::Identity() + P_ss)).norm(), 1e-15);
  EXPECT_LT((Mat2(s.P.block<2, 2>(a, k)) + P_ss).norm(), 1e-15);
  EXPECT_LT((MatX(s.P.block(a, 0, 2, k0)) + MatX(before.P.block(k0, 0, 2, k0))).norm(), 1e-15);
  EXPECT_DOUBLE_EQ(s.P(a + 2, a + 2), sigma_rho0 * sigma_rho0);
  EXPECT_LT((s.P - s.P.transpose()).norm(), 1e-15);
  // Observed in an older clone: (α, β) = z, independent of the rest.
  FilterState older = before;
  addSlamFeatureWithPrior(older, 401, 1, z, 1.0, sigma_rho0, sigma_z);
  const int b = older.featureIndex(2);
  EXPECT_EQ(older.features[2].abr.head<2>(), z);
  EXPECT_EQ(MatX(older.P.block(b, 0, 2, b)).norm(), 0.0);
}

// The whitened rows of an observation (MSCKF, triangulated initialisation)
// gain W on s and lose W ŝ from the residual in the newest clone only.
TEST(ImageShiftState, WhitenedRowsOfTheNewestCloneCarryTheShift) {
  const FilterState s = makeStateWithShift(7);
  const Mat2 W = (Mat2() << 2.0, 0.5, 0.0, 1.5).finished();
  const MatX H0 = MatX::Constant(4, s.dim(), 0.1);
  const VecX r0 = VecX::Constant(4, 0.2);
  MatX H = H0;
  VecX r = r0;
  addImageShiftToRows(s, 2, W, 2, &H, &r);  // rows 2-3, the newest clone
  const int k = s.imageShiftIndex();
  EXPECT_TRUE((MatX(H.block(2, k, 2, 2)) - (MatX::Constant(2, 2, 0.1) + MatX(W))).norm() < 1e-15);
  EXPECT_LT((VecX(r.segment<2>(2)) - (Vec2(0.2, 0.2) - W * s.image_shift)).norm(), 1e-15);
  MatX H_rest = H;
  H_rest.block(2, k, 2, 2) = H0.block(2, k, 2, 2);
  EXPECT_EQ(H_rest, H0);  // nothing else moves
  EXPECT_EQ(VecX(r.head<2>()), VecX(r0.head<2>()));
  MatX H_old = H0;
  VecX r_old = r0;
  addImageShiftToRows(s, 1, W, 2, &H_old, &r_old);  // an older clone: nothing
  EXPECT_EQ(H_old, H0);
  EXPECT_EQ(r_old, r0);
}

// Two steps of dt1 and dt2 are one step of dt1 + dt2, the mean decays by
// exp(−dt/τ), the stationary covariance stays stationary and nothing else moves.
TEST(ImageShiftState, GaussMarkovStepIsExactOverAnyInterval) {
  FilterState a = makeStateWithShift(3);
  FilterState b = a;
  const FilterState before = a;
  decayImageShift(a, 0.013);
  decayImageShift(a, 0.029);
  decayImageShift(b, 0.042);
  EXPECT_LT((a.P - b.P).norm(), 1e-15);
  EXPECT_LT((b.image_shift - std::exp(-0.042 / kShiftTime_s) * before.image_shift).norm(), 1e-15);
  const int k = b.imageShiftIndex();
  EXPECT_EQ(b.P.topLeftCorner(k, k), before.P.topLeftCorner(k, k));
  const double phi = std::exp(-0.042 / kShiftTime_s);
  EXPECT_LT((MatX(b.P.block(k, 0, 2, k)) - phi * MatX(before.P.block(k, 0, 2, k))).norm(), 1e-15);
  FilterState d = makeStateWithShift(4);
  d.P.middleRows(k, 2).setZero();
  d.P.middleCols(k, 2).setZero();
  d.P.block(k, k, 2, 2) = kShiftCov;
  decayImageShift(d, 0.37);
  EXPECT_TRUE(MatX(d.P.block(k, k, 2, 2)).isApprox(MatX(kShiftCov), 1e-14));
  // Without the shift, or for dt ≤ 0, nothing changes.
  FilterState plain;
  plain.P = MatX::Identity(kImuDim, kImuDim);
  decayImageShift(plain, 1.0);
  EXPECT_EQ(plain.P, MatX::Identity(kImuDim, kImuDim));
  FilterState same = makeStateWithShift(5);
  const MatX P_same = same.P;
  decayImageShift(same, 0.0);
  EXPECT_EQ(same.P, P_same);
}

}  // namespace
}  // namespace evio::estimator

// Track errors as states (filter_state.h, feature_dim = 5): the SLAM
// residual's Jacobian over the whole state including e, a new feature's
// covariance (its bearing carries −e), and the Gauss–Markov step's
// exactness over any interval.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "evio/core/random_stream.h"
#include "down_looking_state.h"
#include "numeric_state_jacobian.h"
#include "random_state.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {
namespace {

using test::numericStateJacobian;
using test::randomSpdCovariance;

// Three clones looking down from 10 m, two features added through
// addFeature (so with their track-error blocks), track errors nonzero, and
// a random SPD covariance.
FilterState makeStateWithTrackErrors(std::uint64_t seed) {
  RandomStream rng(seed, "track_error_state");
  FilterState s;
  s.feature_dim = kFeatureDim + kTrackErrorDim;
  s.track_error_cov = Vec2(4e-5, 9e-5).asDiagonal();
  test::addDownLookingClones(s, rng);
  EXPECT_TRUE(test::addTwoGroundFeatures(s));
  for (SlamFeature& f : s.features) f.track_error = Vec2(rng.normal(), rng.normal()) * 0.005;
  s.P = randomSpdCovariance(s.dim(), 1e-3, rng);
  return s;
}

TEST(TrackErrorStates, LayoutHasFiveEntriesPerFeature) {
  const FilterState s = makeStateWithTrackErrors(1);
  EXPECT_EQ(s.dim(), kImuDim + 3 * kCloneDim + 2 * 5);
  EXPECT_EQ(s.featureIndex(1) - s.featureIndex(0), 5);
  EXPECT_EQ(s.sceneDepthIndex(), s.dim());  // no scene depth: one past the last feature
}

TEST(TrackErrorStates, SlamResidualJacobianCoversTheTrackError) {
  const FilterState s = makeStateWithTrackErrors(2);
  const Vec2 z(0.01, -0.02);
  for (std::size_t j = 0; j < s.features.size(); ++j) {
    Eigen::Matrix<double, 2, Eigen::Dynamic> H;
    Vec2 r;
    ASSERT_TRUE(slamResidual(s, j, 2, z, &H, &r));
    // r = z − π(h) − e: H = −∂r/∂δx by central differences over correct().
    const MatX num = numericStateJacobian(
        s,
        [&](const FilterState& x) {
          Eigen::Matrix<double, 2, Eigen::Dynamic> Hx;
          Vec2 rx;
          EXPECT_TRUE(slamResidual(x, j, 2, z, &Hx, &rx));
          return VecX(-rx);
        },
        2);
    EXPECT_LT((MatX(H) - num).norm(), 1e-7) << "feature " << j;
    // The track error enters with the identity, and only the feature's own.
    const int e = s.featureIndex(j) + kFeatureDim;
    EXPECT_TRUE(MatX(H.block(0, e, 2, 2)).isApprox(MatX::Identity(2, 2)));
    const int other = s.featureIndex(1 - j) + kFeatureDim;
    EXPECT_EQ(MatX(H.block(0, other, 2, 2)).norm(), 0.0);
  }
}

TEST(TrackErrorStates, NewFeatureBearingCarriesMinusTheTrackError) {
  // The bearing from an observation z = b + e + n is b̂ = z, so δb = −(e + n):
  // Cov(δb) = Σ_n + Σ_e, Cov(δb, δe) = −Σ_e, Cov(δe) = Σ_e, nothing shared
  // with the rest of the state.
  FilterState s = makeStateWithTrackErrors(3);
  const int before = s.dim();
  Mat3 P_ff = Mat3::Zero();
  P_ff.topLeftCorner<2, 2>() = Vec2(1e-4, 2e-4).asDiagonal();
  P_ff(2, 2) = 0.25;
  Eigen::Matrix<double, 3, Eigen::Dynamic> P_fx = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, before);
  P_fx(2, 0) = 1e-3;  // a cross-covariance of ρ passes through
  SlamFeature f;
  f.id = 200;
  f.anchor_clone_id = 12;
  f.abr = Vec3(0.1, 0.2, 0.5);
  s.addFeature(f, P_ff, P_fx);
  ASSERT_EQ(s.dim(), before + 5);
  const int k = s.featureIndex(2);
  const Mat2& Se = s.track_error_cov;
  EXPECT_TRUE(MatX(s.P.block(k, k, 2, 2)).isApprox(MatX(P_ff.topLeftCorner<2, 2>() + Se)));
  EXPECT_TRUE(MatX(s.P.block(k, k + 3, 2, 2)).isApprox(MatX(-Se)));
  EXPECT_TRUE(MatX(s.P.block(k + 3, k + 3, 2, 2)).isApprox(MatX(Se)));
  EXPECT_DOUBLE_EQ(s.P(k + 2, k + 2), 0.25);
  EXPECT_DOUBLE_EQ(s.P(k + 2, 0), 1e-3);
  EXPECT_EQ(MatX(s.P.block(k + 3, 0, 2, k)).norm(), 0.0);
  EXPECT_EQ(s.features.back().track_error, Vec2::Zero());
  // The block is a covariance: positive semi-definite (here definite).
  const Eigen::LLT<MatX> llt(MatX(s.P.block(k, k, 5, 5)));
  EXPECT_EQ(llt.info(), Eigen::Success);
  // Removing the feature restores the former layout.
  s.removeFeature(2);
  EXPECT_EQ(s.dim(), before);
}

TEST(TrackErrorStates, GaussMarkovStepIsExactOverAnyInterval) {
  // Two steps of dt1 and dt2 are one step of dt1 + dt2 (mean and covariance),
  // the stationary covariance stays stationary, and the mean decays by
  // exp(−dt/τ).
  const double tau = 0.5;
  FilterState a = makeStateWithTrackErrors(4);
  FilterState b = a;
  const Vec2 e0 = a.features[0].track_error;
  decayTrackErrors(a, 0.013, tau);
  decayTrackErrors(a, 0.029, tau);
  decayTrackErrors(b, 0.042, tau);
  EXPECT_LT((a.P - b.P).norm(), 1e-15);
  EXPECT_LT((a.features[0].track_error - b.features[0].track_error).norm(), 1e-15);
  EXPECT_LT((b.features[0].track_error - std::exp(-0.042 / tau) * e0).norm(), 1e-15);
  // Other entries untouched.
  const int k = b.featureIndex(0);
  FilterState c = makeStateWithTrackErrors(4);
  EXPECT_EQ(b.P.topLeftCorner(k + 3, k + 3), c.P.topLeftCorner(k + 3, k + 3));
  // Stationary: P_ee = Σ_e with no cross terms stays Σ_e after any step.
  FilterState d = makeStateWithTrackErrors(5);
  const int e = d.featureIndex(1) + kFeatureDim;
  d.P.middleRows(e, 2).setZero();
  d.P.middleCols(e, 2).setZero();
  d.P.block(e, e, 2, 2) = d.track_error_cov;
  decayTrackErrors(d, 0.37, tau);
  EXPECT_TRUE(MatX(d.P.block(e, e, 2, 2)).isApprox(MatX(d.track_error_cov), 1e-14));
  // Without track-error states: nothing changes.
  FilterState plain;
  plain.P = MatX::Identity(kImuDim, kImuDim);
  decayTrackErrors(plain, 1.0, tau);
  EXPECT_EQ(plain.P, MatX::Identity(kImuDim, kImuDim));
}


TEST(TrackErrorStates, MsckfRowsOfATrackWithASharedErrorAreWhite) {
  // Five clones 40 ms apart along x, 3 m from a point, exactly known; one
  // track observed in all of them with z_i = π_i(p) + e(t_i) + n_i, e a
  // Gauss–Markov error (σ_e 1 px at f = 300, τ 0.5 s) shared by the track, n
  // white (σ 0.3 px). Over 4000 draws the null-space projected rows must
  // have the covariance σ_z² I the update assumes: the mean of the sample
  // covariance's eigenvalues within 5 % of σ_z², the largest within 25 %.
  // Without the shared error's whitening (a state without track errors)
  // the largest eigenvalue is many times σ_z²: the test can fail.
  const double f = 300.0, sigma_z = 0.3 / f, sigma_e = 1.0 / f, tau = 0.5;
  const Vec3 p_W(0.1, -0.05, 3.0);
  const auto makeClones = [](FilterState* s) {
    for (int i = 0; i < 5; ++i) {
      CameraClone c;
      c.id = i;
      c.t_ns = secondsToNs(0.04 * i);
      c.p_W_C = Vec3(0.03 * i, 0.005 * i, 0.0);
      c.q_W_C = Quat::Identity();  // camera z along W's z: the point is in front
      s->clones.push_back(c);
    }
    s->P = MatX::Identity(s->dim(), s->dim()) * 1e-6;
  };
  FilterState with, without;
  with.feature_dim = kFeatureDim + kTrackErrorDim;
  with.track_error_cov = Mat2::Identity() * sigma_e * sigma_e;
  with.track_error_time_s = tau;
  makeClones(&with);
  makeClones(&without);
  RandomStream rng(7, "msckf_shared_error");
  const int draws = 4000, rows = 2 * 5 - 3;
  MatX S_with = MatX::Zero(rows, rows), S_without = MatX::Zero(rows, rows);
  for (int d = 0; d < draws; ++d) {
    FeatureTrack track;
    track.id = 1;
    Vec2 e = Vec2(rng.normal(), rng.normal()) * sigma_e;  // stationary start
    for (std::size_t i = 0; i < 5; ++i) {
      if (i > 0) {
        const double phi = std::exp(-0.04 / tau);
        e = phi * e + std::sqrt(1.0 - phi * phi) * sigma_e * Vec2(rng.normal(), rng.normal());
      }
      const Vec3 h = with.clones[i].R_W_C().transpose() * (p_W - with.clones[i].p_W_C);
      const Vec2 z = h.head<2>() / h.z() + e + Vec2(rng.normal(), rng.normal()) * sigma_z;
      track.observations.push_back({with.clones[i].id, z, Mat2::Identity()});
    }
    MsckfResidual a, b;
    ASSERT_EQ(msckfResidual(with, track, 0.0, TriangulationOptions{}, &a, sigma_z * sigma_z), MsckfOutcome::kOk);
    ASSERT_EQ(msckfResidual(without, track, 0.0, TriangulationOptions{}, &b, sigma_z * sigma_z), MsckfOutcome::kOk);
    ASSERT_EQ(a.r.size(), rows);
    S_with += a.r * a.r.transpose() / draws;
    S_without += b.r * b.r.transpose() / draws;
  }
  const Eigen::SelfAdjointEigenSolver<MatX> ew(S_with / (sigma_z * sigma_z));
  const Eigen::SelfAdjointEigenSolver<MatX> eo(S_without / (sigma_z * sigma_z));
  EXPECT_NEAR(ew.eigenvalues().mean(), 1.0, 0.05);
  EXPECT_LT(ew.eigenvalues().maxCoeff(), 1.25);
  EXPECT_GT(ew.eigenvalues().minCoeff(), 0.75);
  EXPECT_GT(eo.eigenvalues().maxCoeff(), 3.0);
}

}  // namespace
}  // namespace evio::estimator

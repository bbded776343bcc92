// Rotation rows (msckf_update.h rotationResidual): a track without the
// parallax to triangulate, linearised with its depth at the depth prior and
// its bearing and depth projected out, against exact observations and
// first-order expansions; and the MSCKF updater's use of them
// (msckf_rotation_rows).
#include <gtest/gtest.h>

#include <cmath>

#include "evio/core/so3.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/msckf_updater.h"
#include "evio/estimator/backend/visual_models.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));
constexpr double kSigmaZ2 = 1e-4;  // σ_z² of a whitened row (1 px at f = 100 px)
constexpr double kRho0 = 0.5;      // the depth prior: 2 m
constexpr double kSigmaRho0 = 0.25;

/// n clones turning about the same point (the camera at p_W_C = baseline · i
/// along +x of W), up to `turn_rad` about an axis near the viewing direction's normal.
FilterState turningClones(int n, double turn_rad, double baseline_m = 0.0) {
  FilterState s = test::restingState(n, 1e-4);
  for (int i = 0; i < n; ++i) {
    const double u = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
    CameraClone& c = s.clones[static_cast<std::size_t>(i)];
    c.q_W_C = Quat(so3::exp(Vec3(0.3, 1.0, 0.2).normalized() * (turn_rad * u)));
    c.p_W_C = Vec3(baseline_m * i, 0.0, 0.0);
    c.q_fej = c.q_W_C;
    c.p_fej = c.p_W_C;
  }
  return s;
}

FeatureTrack exactTrack(const FilterState& s, const Vec3& p_W) {
  FeatureTrack t;
  t.id = 7;
  for (const CameraClone& c : s.clones) {
    Vec2 z;
    EXPECT_TRUE(projectWorldPoint(c, p_W, &z));
    t.observations.push_back({c.id, z});
  }
  return t;
}

TEST(RotationRows, ExactObservationsOfATurningCameraGiveZeroResidualsAtAnyDepth) {
  // The camera turns 0.3 rad in place: a point 0.8 m or 50 m away projects
  // as it would at the prior's 2 m, so the residual is zero to rounding.
  const FilterState s = turningClones(5, 0.3);
  for (const double depth : {0.8, 50.0}) {
    const FeatureTrack t = exactTrack(s, Vec3(0.1, -0.05, depth));
    MsckfResidual res;
    ASSERT_EQ(rotationResidual(s, t, &res, kSigmaZ2, kRho0, kSigmaRho0), MsckfOutcome::kOk);
    EXPECT_EQ(res.r.size(), 2 * 5 - 3);
    EXPECT_EQ(res.H.cols(), s.dim());
    EXPECT_LT(res.r.norm(), 1e-12) << depth;
    EXPECT_EQ(res.p_W, Vec3::Zero());
  }
}

TEST(RotationRows, TwoObservationsGiveOneRowAndOneIsTooShort) {
  const FilterState s = turningClones(2, 0.1);
  MsckfResidual res;
  ASSERT_EQ(rotationResidual(s, exactTrack(s, Vec3(0, 0, 2)), &res, kSigmaZ2, kRho0, kSigmaRho0), MsckfOutcome::kOk);
  EXPECT_EQ(res.r.size(), 1);
  FeatureTrack one = exactTrack(s, Vec3(0, 0, 2));
  one.observations.resize(1);
  EXPECT_EQ(rotationResidual(s, one, &res, kSigmaZ2, kRho0, kSigmaRho0), MsckfOutcome::kTooShort);
}

TEST(RotationRows, TheRowsPredictAnAttitudeErrorToFirstOrder) {
  // Observations from the true clones; the estimate's attitudes are off by
  // δθ_i (R = R̂ Exp(δθ), filter_state.h). Then r = H δx + O(|δθ|²): with
  // |δθ| ~ 1e-4 rad the residual is ~1e-4 and what H does not explain ~1e-8.
  const FilterState truth = turningClones(6, 0.4);
  const FeatureTrack t = exactTrack(truth, Vec3(0.2, 0.1, 3.0));
  FilterState est = truth;
  VecX dx = VecX::Zero(est.dim());
  for (std::size_t i = 0; i < est.clones.size(); ++i) {
    const Vec3 dtheta = 1e-4 * Vec3(std::sin(1.0 + i), std::cos(2.0 * i), std::sin(0.5 * i - 1.0));
    est.clones[i].q_W_C = Quat(truth.clones[i].R_W_C() * so3::exp(-dtheta));
    dx.segment<3>(est.cloneIndex(i) + 3) = dtheta;
  }
  MsckfResidual res;
  ASSERT_EQ(rotationResidual(est, t, &res, kSigmaZ2, kRho0, kSigmaRho0), MsckfOutcome::kOk);
  const VecX predicted = res.H * dx;
  EXPECT_GT(res.r.norm(), 1e-5);
  EXPECT_LT((res.r - predicted).norm(), 1e-3 * res.r.norm());
}

TEST(RotationRows, AtThePriorsDepthTheRowsPredictAPositionErrorToFirstOrder) {
  // The clones' positions are off by δp_i (p = p̂ + δp) while the camera
  // also turns; the point stands at the prior's depth. Linearised there, the
  // rows see the positions as a triangulated track's rows would: r = H δx
  // to first order. (At another depth the difference is the product of the
  // depth's error and δp: second order.)
  const FilterState truth = turningClones(5, 0.3, 0.001);
  const Vec3 p_W = truth.clones.back().p_W_C + truth.clones.back().R_W_C() * Vec3(0.05, -0.1, 1.0) / kRho0;
  const FeatureTrack t = exactTrack(truth, p_W);
  FilterState est = truth;
  VecX dx = VecX::Zero(est.dim());
  for (std::size_t i = 0; i + 1 < est.clones.size(); ++i) {  // the anchor stays: its own error is the point's
    const Vec3 dp = 2e-4 * Vec3(std::cos(1.0 + i), std::sin(3.0 * i), std::cos(0.7 * i));
    est.clones[i].p_W_C = truth.clones[i].p_W_C - dp;
    dx.segment<3>(est.cloneIndex(i)) = dp;
  }
  MsckfResidual res;
  ASSERT_EQ(rotationResidual(est, t, &res, kSigmaZ2, kRho0, 1e-6), MsckfOutcome::kOk);
  EXPECT_GT(res.r.norm(), 1e-5);
  EXPECT_LT((res.r - res.H * dx).norm(), 1e-2 * res.r.norm());
}

TEST(RotationRows, TranslationIsProjectedOutToFirstOrder) {
  // A point 1 m away, the prior at 2 m, seen while the camera moves along
  // x: the flow of the translation at the wrong depth is first order in the
  // baseline b and enters the rows only at second order, so halving b
  // quarters the residual.
  const Vec3 p_W(0.1, 0.05, 1.0);
  double previous = 0.0;
  for (const double b : {0.004, 0.002, 0.001}) {
    const FilterState s = turningClones(5, 0.2, b);
    MsckfResidual res;
    ASSERT_EQ(rotationResidual(s, exactTrack(s, p_W), &res, kSigmaZ2, kRho0, 1e-6), MsckfOutcome::kOk);
    const double norm = res.r.norm();
    EXPECT_GT(norm, 0.0);
    // The translation's own flow, b / depth per clone step, is far larger.
    EXPECT_LT(norm, 0.05 * b / p_W.z());
    if (previous > 0.0) {
      EXPECT_NEAR(previous / norm, 4.0, 0.4) << b;
    }
    previous = norm;
  }
}

TEST(RotationRows, TheUpdaterUsesATrackWithoutParallaxOnlyWhenAsked) {
  // Three clones turning in place: no parallax. Off, the track is dropped
  // (xVIO); on, it gives 2n − 3 rows, counted as rotation rows.
  for (const bool on : {false, true}) {
    test::UpdaterBench b(turningClones(3, 0.2));
    b.options.msckf_rotation_rows = on;
    TrackMap tracks{{7, exactTrack(b.state, Vec3(0.1, 0.0, 2.0))}};
    MsckfUpdater msckf(b.context(), kCamera, 1e-4, &b.chi2);
    const UpdateRows rows = msckf.residuals({7}, &tracks);
    EXPECT_EQ(b.stats.msckf_features_no_parallax, 1);
    EXPECT_EQ(rows.H.rows(), on ? 3 : 0);
    EXPECT_EQ(b.stats.msckf_rotation_used, on ? 1 : 0);
    EXPECT_EQ(b.stats.msckf_features_used, on ? 1 : 0);
    EXPECT_TRUE(b.triangulated.points().empty());  // no depth learnt from it
    if (on) {
      EXPECT_LT(rows.r.norm(), 1e-12);
    }
  }
}

TEST(RotationRows, IteratedUpdatesRelinearizeRotationRowsAsRotationRows) {
  test::UpdaterBench b(turningClones(4, 0.3));
  b.options.msckf_rotation_rows = true;
  b.options.msckf_iterations = 3;
  TrackMap tracks{{7, exactTrack(b.state, Vec3(0.1, 0.0, 2.0))}};
  MsckfUpdater msckf(b.context(), kCamera, 1e-4, &b.chi2);
  const UpdateRows rows = msckf.residuals({7}, &tracks);
  ASSERT_EQ(rows.H.rows(), 5);
  const UpdateRows again = msckf.relinearize(b.state);
  ASSERT_EQ(again.H.rows(), 5);
  EXPECT_TRUE(again.H == rows.H);
  EXPECT_TRUE(again.r == rows.r);
}

}  // namespace
}  // namespace evio::estimator

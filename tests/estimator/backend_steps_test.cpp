// The updaters' shared services (updater.h, aux_updaters.h, slam_updater.h,
// msckf_updater.h) and the scene depth, each on its own, against exact
// answers; the steps that choose the features are in feature_selection_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <unordered_set>
#include <utility>

#include "evio/core/so3.h"
#include "evio/estimator/backend/aux_updaters.h"
#include "evio/estimator/backend/feature_selection.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/msckf_updater.h"
#include "evio/estimator/backend/scene_depth.h"
#include "evio/estimator/backend/slam_updater.h"
#include "evio/estimator/backend/visual_models.h"
#include "track_builders.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));

using test::restingState;
using test::track;
using test::tracksOf;

using test::UpdaterBench;

TEST(BackendUpdaters, ConstrainRemovesTheYawDirectionExactlyOnce) {
  FilterState state = restingState(2);
  state.imu.p_W_B = Vec3(1, 2, 3);
  state.imu.v_W = Vec3(0.5, -0.2, 0.1);
  state.clones[1].p_fej = Vec3(0.3, 0.1, 0.0);
  UpdaterBench b(state);
  b.options.observability_constraint = true;
  ZeroVelocityUpdater updater(b.context());
  MatX H = MatX::Ones(3, b.state.dim());
  updater.constrain(&H);
  const VecX n = b.state.yawDirection(b.fej);
  EXPECT_LT((H * n).norm(), 1e-12 * n.norm());
  b.options.observability_constraint = false;
  MatX H2 = MatX::Ones(3, b.state.dim());
  updater.constrain(&H2);
  EXPECT_TRUE(H2.isApprox(MatX::Ones(3, b.state.dim())));
}

TEST(BackendUpdaters, ConstrainKeepsRowsBlindToGlobalTranslation) {
  // Rows blind to a global translation t (every position state moved by the
  // same a: H t = 0) must stay blind after the yaw direction is projected out,
  // or the constraint itself adds translation (and through it yaw) information.
  FilterState state = restingState(3);
  state.imu.p_W_B = Vec3(1, 2, 3);
  state.imu.v_W = Vec3(0.5, -0.2, 0.1);
  state.clones[0].p_fej = Vec3(0.3, 0.1, 0.0);
  state.clones[1].p_fej = Vec3(-0.4, 1.1, 0.2);
  state.clones[2].p_fej = Vec3(2.0, -0.7, 1.5);
  UpdaterBench b(state);
  b.options.observability_constraint = true;
  ZeroVelocityUpdater updater(b.context());
  const auto translation = [&b](int axis) {
    VecX t = VecX::Zero(b.state.dim());
    t(kIdxP + axis) = 1.0;
    for (std::size_t i = 0; i < b.state.clones.size(); ++i) t(b.state.cloneIndex(i) + kCloneP + axis) = 1.0;
    return t;
  };
  // Random rows, made blind to the three translations by projection.
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  MatX H(4, b.state.dim());
  for (Eigen::Index i = 0; i < H.size(); ++i) H.data()[i] = normal(rng);
  MatX T(b.state.dim(), 3);
  for (int a = 0; a < 3; ++a) T.col(a) = translation(a);
  H -= H * T * (T.transpose() * T).inverse() * T.transpose();
  updater.constrain(&H);
  const VecX n = b.state.yawDirection(b.fej);
  EXPECT_LT((H * n).norm(), 1e-12 * H.norm() * n.norm());
  for (int a = 0; a < 3; ++a) EXPECT_LT((H * translation(a)).norm(), 1e-12 * H.norm()) << "axis " << a;
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(n.dot(translation(a)), 0.0, 1e-12) << "axis " << a;
  // The rotation is about the vertical through the centroid of the four
  // positions (1, 2, 3), (0.3, 0.1, 0), (−0.4, 1.1, 0.2), (2, −0.7, 1.5):
  // c = (0.725, 0.625, 1.175), so δp = e_z × (p − c).
  const Vec3 c(0.725, 0.625, 1.175);
  EXPECT_TRUE(n.segment<3>(kIdxP).isApprox(Vec3::UnitZ().cross(Vec3(1, 2, 3) - c), 1e-12));
  EXPECT_TRUE(n.segment<3>(b.state.cloneIndex(2) + kCloneP)
                  .isApprox(Vec3::UnitZ().cross(Vec3(2.0, -0.7, 1.5) - c), 1e-12));
}

TEST(BackendUpdaters, ZeroVelocityUpdateIsTheScalarKalmanGainPerAxis) {
  // P_vv = p I, σ = s: v⁺ = v̂ s²/(p + s²), P_vv⁺ = p s²/(p + s²) (no cross terms).
  FilterState state = restingState(0, 0.04);
  state.imu.v_W = Vec3(1.0, -2.0, 0.5);
  UpdaterBench b(state);
  b.options.observability_constraint = false;
  b.options.zero_velocity_sigma_mps = 0.1;
  ZeroVelocityUpdater updater(b.context());
  ASSERT_TRUE(updater.update());
  const double k = 0.01 / (0.04 + 0.01);
  EXPECT_TRUE(b.state.imu.v_W.isApprox(Vec3(1.0, -2.0, 0.5) * k, 1e-12));
  EXPECT_NEAR(b.state.P(kIdxV, kIdxV), 0.04 * k, 1e-15);
  EXPECT_NEAR(b.state.P(kIdxP, kIdxP), 0.04, 1e-15);  // uncorrelated: untouched
  EXPECT_EQ(b.stats.zero_velocity_updates, 1);
}

TEST(BackendUpdaters, RangeOutsideTheSensorsSpanIsRejectedAndKeepsTheState) {
  UpdaterBench b(restingState(0));
  RangeFinderSensor sensor;
  sensor.min_range_m = 0.5;
  sensor.max_range_m = 10.0;
  RangeUpdater updater(b.context(), sensor, &b.chi2);
  const MatX P = b.state.P;
  EXPECT_TRUE(updater.update(20.0));
  EXPECT_TRUE(updater.update(0.1));
  EXPECT_EQ(b.stats.range_rejected, 2);
  EXPECT_FALSE(updater.latestHit().has_value());
  // In range but no SLAM features to form a plane: rejected, the hit point kept
  // for depth priors (origin + 4 m along the beam, +z of B here).
  EXPECT_TRUE(updater.update(4.0));
  EXPECT_EQ(b.stats.range_rejected, 3);
  ASSERT_TRUE(updater.latestHit().has_value());
  EXPECT_TRUE(updater.latestHit()->second.isApprox(Vec3(0, 0, 4)));
  EXPECT_TRUE(b.state.P.isApprox(P));
}

TEST(BackendUpdaters, SlamPruneDropsGatedOutAndNonFiniteFeatures) {
  FilterState state = restingState(1);
  for (FeatureId id = 0; id < 4; ++id) {
    SlamFeature f;
    f.id = id;
    f.abr = Vec3(0.0, 0.0, 1.0);
    state.features.push_back(f);
  }
  state.features[3].abr.z() = std::numeric_limits<double>::quiet_NaN();
  state.P = MatX::Identity(state.dim(), state.dim());
  UpdaterBench b(state);
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  slam.prune({2, 0});
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_EQ(b.state.features[0].id, 1);
  EXPECT_EQ(b.state.dim(), kImuDim + kCloneDim + kFeatureDim);
  EXPECT_EQ(b.stats.slam_features_removed, 3);
}

TEST(BackendUpdaters, TrackDriftWidensEveryBearingByTheWalkOverTheInterval) {
  // P_αα += q Δt / f_x², P_ββ += q Δt / f_y², nothing else: q = 2 px²/s over
  // 0.05 s at f_x = 100 px, f_y = 80 px.
  const Camera camera(PinholeCamera(200, 100, Vec4(100, 80, 100, 50)));
  FilterState state = restingState(1);
  for (FeatureId id = 0; id < 2; ++id) {
    SlamFeature f;
    f.id = id;
    f.abr = Vec3(0.1, -0.2, 0.5);
    state.features.push_back(f);
  }
  state.P = MatX::Identity(state.dim(), state.dim()) * 1e-4;
  state.P(state.featureIndex(0), state.featureIndex(1)) = state.P(state.featureIndex(1), state.featureIndex(0)) = 3e-5;
  UpdaterBench b(state);
  SlamUpdater slam(b.context(), camera, 0.01, &b.chi2, &b.chi2, nullptr);
  slam.diffuseBearings(0.05);  // the option is off: nothing changes
  EXPECT_EQ(b.state.P, state.P);
  b.options.slam_bearing_walk_px2_per_s = 2.0;
  slam.diffuseBearings(0.05);
  MatX expected = state.P;
  for (std::size_t j = 0; j < 2; ++j) {
    expected(state.featureIndex(j), state.featureIndex(j)) += 2.0 * 0.05 / (100.0 * 100.0);
    expected(state.featureIndex(j) + 1, state.featureIndex(j) + 1) += 2.0 * 0.05 / (80.0 * 80.0);
  }
  EXPECT_EQ((b.state.P - expected).cwiseAbs().maxCoeff(), 0.0);
}

TEST(BackendUpdaters, MsckfUsesEveryChosenTrackOnceAndCountsWhyNot) {
  // Two clones with no baseline: no parallax for any track; each chosen track is emptied.
  UpdaterBench b(restingState(2));
  MsckfUpdater msckf(b.context(), kCamera, 1e-4, &b.chi2);
  TrackMap tracks = tracksOf({track(1, {0, 1}), track(2, {0, 1})});
  const UpdateRows rows = msckf.residuals({1, 2}, &tracks);
  EXPECT_EQ(rows.H.rows(), 0);
  EXPECT_EQ(rows.H.cols(), b.state.dim());
  EXPECT_EQ(msckf.lastCount(), 0);
  EXPECT_EQ(b.stats.msckf_features_no_parallax + b.stats.msckf_triangulation_failed, 2);
  EXPECT_TRUE(tracks[1].observations.empty());
  EXPECT_TRUE(tracks[2].observations.empty());
}

/// Clones along +x of W (identity attitude: the cameras look along +z of W).
FilterState cloneRow(const std::vector<double>& x_m, double p_var = 1e-4) {
  FilterState s = restingState(static_cast<int>(x_m.size()), p_var);
  for (std::size_t i = 0; i < x_m.size(); ++i) s.clones[i].p_W_C = s.clones[i].p_fej = Vec3(x_m[i], 0, 0);
  return s;
}

TEST(BackendUpdaters, MsckfGivesTwoNMinusThreeRowsAndZeroResidualsForExactObservations) {
  // A point 1 m ahead seen from three clones 0.25 m apart: 50 px of parallax at f = 100 px.
  UpdaterBench b(cloneRow({0.0, 0.25, 0.5}));
  const Vec3 p_W(0.25, 0.1, 1.0);
  FeatureTrack t;
  t.id = 4;
  for (const CameraClone& c : b.state.clones) {
    Vec2 z;
    ASSERT_TRUE(projectWorldPoint(c, p_W, &z));
    t.observations.push_back({c.id, z});
  }
  TrackMap tracks{{4, t}};
  MsckfUpdater msckf(b.context(), kCamera, 1e-4, &b.chi2);
  const UpdateRows rows = msckf.residuals({4}, &tracks);
  ASSERT_EQ(rows.H.rows(), 3);  // 2n − 3, n = 3
  EXPECT_EQ(rows.H.cols(), b.state.dim());
  EXPECT_LT(rows.r.norm(), 1e-9);
  EXPECT_EQ(msckf.lastCount(), 1);
  EXPECT_EQ(b.stats.msckf_features_used, 1);
  EXPECT_TRUE(tracks[4].observations.empty());
  // The triangulated point is remembered for the depth prior from the map.
  ASSERT_EQ(b.triangulated.points().size(), 1u);
  EXPECT_LT((b.triangulated.points()[0] - p_W).norm(), 1e-9);
}

// The iterated MSCKF update's rows: at the state residuals() saw, the
// re-triangulated rows are those rows (the same function of the same
// inputs, bit for bit); at a state whose clones moved they are the rows
// linearised there: the residual of observations that were exact for the
// first clones is no longer zero, and the Jacobian follows the clones.
TEST(BackendUpdaters, MsckfRowsRelinearizedAtAnIterateAreTheRowsOfThatState) {
  UpdaterBench b(cloneRow({0.0, 0.25, 0.5}));
  b.options.msckf_iterations = 3;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  TrackMap tracks;
  for (FeatureId id = 1; id <= 3; ++id) {
    const Vec3 p_W(0.25 + 0.1 * static_cast<double>(id), 0.1 - 0.05 * static_cast<double>(id), 1.0 + 0.2 * static_cast<double>(id));
    FeatureTrack t;
    t.id = id;
    for (const CameraClone& c : b.state.clones) {
      Vec2 z;
      ASSERT_TRUE(projectWorldPoint(c, p_W, &z));
      t.observations.push_back({c.id, z + Vec2(noise(rng), noise(rng))});
    }
    tracks[id] = t;
  }
  TrackMap untouched = tracks;  // residuals() empties the tracks it uses
  MsckfUpdater msckf(b.context(), kCamera, 1e-4, &b.chi2);
  const UpdateRows rows = msckf.residuals({1, 2, 3}, &tracks);
  ASSERT_EQ(msckf.lastCount(), 3);
  const UpdateRows again = msckf.relinearize(b.state);
  ASSERT_EQ(again.H.rows(), rows.H.rows());
  EXPECT_TRUE(again.H == rows.H);
  EXPECT_TRUE(again.r == rows.r);

  FilterState moved = b.state;
  moved.clones[2].p_W_C += Vec3(0.0, 0.02, 0.0);
  const UpdateRows there = msckf.relinearize(moved);
  ASSERT_EQ(there.H.rows(), rows.H.rows());
  EXPECT_GT((there.r - rows.r).norm(), 1e-3);
  EXPECT_GT((there.H - rows.H).norm(), 1e-6);
  // Without iterations the tracks are not kept: nothing to re-linearise.
  UpdaterBench once(cloneRow({0.0, 0.25, 0.5}));
  MsckfUpdater plain(once.context(), kCamera, 1e-4, &once.chi2);
  EXPECT_EQ(plain.residuals({1, 2, 3}, &untouched).H.rows(), rows.H.rows());
  EXPECT_EQ(plain.relinearize(once.state).H.rows(), 0);
}

// With per-observation covariances R_i = σ_z² W_i⁻¹ W_i⁻ᵀ and P → 0, the
// whitened, null-space projected MSCKF residual has squared norm / σ_z²
// equal to the generalised least-squares statistic over the point,
//   min_δ (r − H_f δ)ᵀ R⁻¹ (r − H_f δ),
// computed here without any projection.
TEST(BackendUpdaters, MsckfWhitenedResidualIsTheGeneralisedLeastSquaresStatistic) {
  const FilterState state = cloneRow({0.0, 0.25, 0.5, 0.75}, 1e-14);
  const Vec3 p_W(0.3, 0.1, 1.0);
  const double sigma_z = 0.01;
  const std::vector<Mat2> covs = {Vec2(1e-4, 4e-4).asDiagonal(), (Mat2() << 2e-4, 1e-4, 1e-4, 3e-4).finished(),
                                  Vec2(9e-4, 1e-4).asDiagonal(), 1e-4 * Mat2::Identity()};
  const std::vector<Vec2> noise = {Vec2(0.01, -0.02), Vec2(-0.015, 0.01), Vec2(0.03, 0.005), Vec2(-0.01, -0.01)};
  FeatureTrack t;
  t.id = 4;
  for (std::size_t i = 0; i < state.clones.size(); ++i) {
    Vec2 z;
    ASSERT_TRUE(projectWorldPoint(state.clones[i], p_W, &z));
    t.observations.push_back({state.clones[i].id, z + noise[i], whiteningFor(covs[i], sigma_z)});
  }
  MsckfResidual res;
  ASSERT_EQ(msckfResidual(state, t, 0.0, TriangulationOptions{}, &res), MsckfOutcome::kOk);
  ASSERT_EQ(res.r.size(), 5);
  // The statistic from the stacked, unwhitened model at the same point.
  const Eigen::Index m = 8;
  VecX r(m);
  MatX H_f(m, 3);
  MatX R_inv = MatX::Zero(m, m);
  for (std::size_t i = 0; i < state.clones.size(); ++i) {
    Vec2 zh;
    Mat23 Hp;
    ASSERT_TRUE(projectWorldPoint(state.clones[i], res.p_W, &zh, nullptr, &Hp));
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
    r.segment<2>(row) = t.observations[i].z - zh;
    H_f.middleRows<2>(row) = Hp;
    R_inv.block<2, 2>(row, row) = covs[i].inverse();
  }
  const Mat3 A = H_f.transpose() * R_inv * H_f;
  const double gls = r.dot(R_inv * r) - (H_f.transpose() * R_inv * r).dot(A.ldlt().solve(H_f.transpose() * R_inv * r));
  EXPECT_NEAR(res.r.squaredNorm() / (sigma_z * sigma_z), gls, 1e-6 * gls);
  EXPECT_GT(gls, 1.0);
}

TEST(BackendUpdaters, SlamGateAcceptsThePredictionAndGatesOutRepeatedOutliers) {
  // Feature (α, β, ρ) = (0.1, −0.2, 0.5) anchored in clone 0; clone 1 at the same pose sees it at (α, β).
  UpdaterBench b(cloneRow({0.0, 0.0}));
  SlamFeature f;
  f.id = 9;
  f.anchor_clone_id = 0;
  f.abr = Vec3(0.1, -0.2, 0.5);
  b.state.features.push_back(f);
  b.state.P = 1e-4 * MatX::Identity(b.state.dim(), b.state.dim());
  b.options.slam_max_gate_failures = 2;
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  SlamGate g = slam.gate({{9, Vec2(0.1, -0.2)}, {5, Vec2::Zero()}}, 1);  // 5 is no SLAM feature
  ASSERT_EQ(g.accepted.size(), 1u);
  EXPECT_EQ(g.accepted[0].id, 9);
  EXPECT_TRUE(g.gated_out.empty());
  MatX H;
  VecX r;
  slam.relinearize(b.state, g.accepted, 1, &H, &r);
  ASSERT_EQ(H.rows(), 2);
  EXPECT_LT(r.norm(), 1e-12);
  const std::vector<FeatureObservation> outlier{{9, Vec2(0.6, 0.3)}};  // 0.5 away, σ 0.01
  g = slam.gate(outlier, 1);
  EXPECT_TRUE(g.accepted.empty());
  EXPECT_TRUE(g.gated_out.empty());  // one failure of two
  g = slam.gate(outlier, 1);
  EXPECT_EQ(g.gated_out, (std::vector<std::size_t>{0}));
  EXPECT_EQ(b.stats.slam_updates_rejected, 2);
  slam.marginalizeUnobserved({});
  EXPECT_TRUE(b.state.features.empty());
  EXPECT_EQ(b.stats.slam_features_removed, 1);
}

TEST(BackendUpdaters, ANewSlamFeatureCountsItsInitialisationAsItsLastUpdate) {
  UpdaterBench b(cloneRow({0.0, 0.0}));
  b.state.clones[0].t_ns = secondsToNs(1.0);
  b.state.clones[1].t_ns = secondsToNs(1.25);
  b.options.slam_min_depth_m = 0.5;
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks{{3, track(3, {0, 1})}};
  tracks[3].observations.back().z = Vec2(0.2, 0.1);
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_EQ(b.state.features[0].last_update_ns, secondsToNs(1.25));  // the track's last clone, where it enters
  EXPECT_EQ(b.state.features[0].last_update_z, Vec2(0.2, 0.1));     // and its observation there
}

TEST(BackendUpdaters, SlamInitialisationWithoutParallaxTakesTheDepthPrior) {
  // Two clones at one pose: no parallax, so the track enters with ρ0 = 1/(2 d_min), σ = 1/(4 d_min).
  UpdaterBench b(cloneRow({0.0, 0.0}));
  b.options.slam_min_depth_m = 0.5;
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks{{3, track(3, {0, 1})}};
  tracks[3].observations.back().z = Vec2(0.2, 0.1);
  ASSERT_TRUE(slam.initialize({3, 8}, &tracks));  // 8 has no track: skipped
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_EQ(b.state.features[0].id, 3);
  EXPECT_EQ(b.state.features[0].anchor_clone_id, 1);
  EXPECT_TRUE(b.state.features[0].abr.isApprox(Vec3(0.2, 0.1, 1.0)));
  const int j = b.state.featureIndex(0);
  EXPECT_NEAR(b.state.P(j + 2, j + 2), 0.5 * 0.5, 1e-15);
  EXPECT_EQ(b.stats.slam_initialized_prior, 1);
  EXPECT_TRUE(tracks.empty());
}

TEST(BackendUpdaters, BeforeTheFixedPriorsWaitATrackStaysInTheWindowUntilTheMapKnowsTheDepth) {
  // slam_fixed_prior_wait_s = 2 s: at 1.5 s after initialisation, with no
  // parallax and no map depth, the track is left where it was and counted;
  // once the map has three points it enters with the map's prior; without
  // the map, at 2 s it takes the fixed prior.
  UpdaterBench b(cloneRow({0.0, 0.0}));
  b.options.slam_min_depth_m = 0.5;
  b.options.slam_fixed_prior_wait_s = 2.0;
  b.initialized_at = secondsToNs(10.0);
  b.state.imu.t_ns = secondsToNs(11.5);
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks{{3, track(3, {0, 1})}, {4, track(4, {0, 1})}};
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  EXPECT_TRUE(b.state.features.empty());
  ASSERT_EQ(tracks.count(3), 1u);
  EXPECT_EQ(tracks[3].observations.size(), 2u);
  EXPECT_EQ(b.stats.slam_waiting_for_depth, 1);
  EXPECT_EQ(b.stats.slam_initialized_prior, 0);

  b.state.imu.t_ns = secondsToNs(12.0);  // the wait is over: the fixed prior
  ASSERT_TRUE(slam.initialize({4}, &tracks));
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_DOUBLE_EQ(b.state.features[0].abr.z(), 1.0);
  EXPECT_EQ(b.stats.slam_initialized_prior, 1);

  b.state.imu.t_ns = secondsToNs(11.0);  // (a clock back in the wait) the map's depth needs no wait
  for (const double z : {2.0, 2.5, 4.0}) b.triangulated.add(Vec3(0.3, -0.2, z));
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  ASSERT_EQ(b.state.features.size(), 2u);
  EXPECT_DOUBLE_EQ(b.state.features[1].abr.z(), 1.0 / 2.5);
  EXPECT_EQ(b.stats.slam_initialized_map, 1);
  EXPECT_TRUE(tracks.empty());
}

TEST(BackendUpdaters, SlamInitialisationWithoutParallaxTakesTheMapDepthOnceTheFilterHasTriangulated) {
  // Three triangulated points 2, 2.5 and 4 m in front of the clones (which
  // look along +z of W): the lower median of 1/z is 1/2.5, so the feature
  // enters with ρ0 = 0.4, σ = ρ0/2 (the fixed prior's shape), not the fixed 1 m prior.
  UpdaterBench b(cloneRow({0.0, 0.0}));
  b.options.slam_min_depth_m = 0.5;
  for (const double z : {2.0, 2.5, 4.0}) b.triangulated.add(Vec3(0.3, -0.2, z));
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks{{3, track(3, {0, 1})}};
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_DOUBLE_EQ(b.state.features[0].abr.z(), 1.0 / 2.5);
  const int j = b.state.featureIndex(0);
  EXPECT_NEAR(b.state.P(j + 2, j + 2), 0.2 * 0.2, 1e-15);
  EXPECT_EQ(b.stats.slam_initialized_map, 1);
  EXPECT_EQ(b.stats.slam_initialized_prior, 0);

  // Below map_prior_min_points, or with the map prior off: the fixed prior.
  for (const bool from_map : {true, false}) {
    UpdaterBench c(cloneRow({0.0, 0.0}));
    c.options.slam_min_depth_m = 0.5;
    c.options.depth_prior_from_map = from_map;
    c.options.map_prior_min_points = from_map ? 4 : 3;
    for (const double z : {2.0, 2.5, 4.0}) c.triangulated.add(Vec3(0.3, -0.2, z));
    SlamUpdater fixed(c.context(), kCamera, 0.01, &c.chi2, &c.chi2, nullptr);
    TrackMap t{{3, track(3, {0, 1})}};
    ASSERT_TRUE(fixed.initialize({3}, &t));
    EXPECT_DOUBLE_EQ(c.state.features[0].abr.z(), 1.0) << from_map;
    EXPECT_EQ(c.stats.slam_initialized_prior, 1) << from_map;
  }
}

TEST(SceneDepth, MedianInverseDepthIsOverThePointsInFrontOfTheClone) {
  // A clone at (1, 2, 3) turned 90° about x of W: its optical axis (+z of C) is −y of W.
  CameraClone clone;
  clone.p_W_C = Vec3(1, 2, 3);
  clone.q_W_C = Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitX()));
  ASSERT_LT((clone.R_W_C() * Vec3::UnitZ() - Vec3(0, -1, 0)).norm(), 1e-15);
  std::vector<Vec3> points;
  for (const double depth : {1.0, 2.0, 4.0, 8.0}) points.push_back(clone.p_W_C + Vec3(0.1, -depth, 0.2));
  points.push_back(clone.p_W_C + Vec3(0.0, 3.0, 0.0));  // behind: skipped
  // 1/z = 1, 0.5, 0.25, 0.125: the lower median of four is the second smallest, 0.25.
  const auto rho = medianInverseDepth(clone, points, 4);
  ASSERT_TRUE(rho.has_value());
  EXPECT_NEAR(*rho, 0.25, 1e-15);
  EXPECT_FALSE(medianInverseDepth(clone, points, 5).has_value());
  EXPECT_FALSE(medianInverseDepth(clone, {}, 1).has_value());
}

TEST(SceneDepth, TriangulatedPointsKeepTheLatestCapacityPoints) {
  TriangulatedPoints memory(3);
  for (int i = 0; i < 5; ++i) memory.add(Vec3(i, 0, 1));
  memory.add(Vec3(std::nan(""), 0, 1));  // not finite: ignored
  std::vector<double> x;
  for (const Vec3& p : memory.points()) x.push_back(p.x());
  std::sort(x.begin(), x.end());
  EXPECT_EQ(x, (std::vector<double>{2, 3, 4}));
}

TEST(SceneDepth, ConvergedSlamPointsAreTheFeaturesWhoseDepthTheDataFixed) {
  // Two features anchored in clone 1 (at x = 0.5), both at ρ = 0.5 (2 m):
  // σ_ρ = 0.05 (10 % of ρ) counts, σ_ρ = 0.25 (50 %, a fresh depth prior) does not.
  FilterState s = cloneRow({0.0, 0.5});
  for (int k = 0; k < 2; ++k) {
    SlamFeature f;
    f.id = k;
    f.anchor_clone_id = 1;
    f.abr = Vec3(0.1, -0.2, 0.5);
    Mat3 P_ff = 1e-6 * Mat3::Identity();
    P_ff(2, 2) = k == 0 ? 0.05 * 0.05 : 0.25 * 0.25;
    s.addFeature(f, P_ff, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, s.dim()));
  }
  const std::vector<Vec3> points = convergedSlamPoints(s, 0.25);
  ASSERT_EQ(points.size(), 1u);
  EXPECT_LT((points[0] - Vec3(0.5 + 0.1 * 2.0, -0.2 * 2.0, 2.0)).norm(), 1e-12);
}

}  // namespace
}  // namespace evio::estimator

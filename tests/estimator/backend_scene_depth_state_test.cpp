// The scene's inverse depth ρ_s as a state (BackendOptions::slam_scene_depth_share,
// filter_state.h, slam_features.h): its place in the error state, the
// features that share it, and what one feature's update tells the others,
// against the exact Gaussian answers of the hierarchical model
// ρ_i = ρ_s + δ_i.
#include <gtest/gtest.h>

#include <cmath>

#include "evio/core/error.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/slam_updater.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));

/// Clones 0..n-1 at the origin looking along +z, P = 1e-4 I.
FilterState clonesAtRest(int n) { return test::restingState(n, 1e-4); }

TEST(SceneDepthState, TheSceneDepthIsTheLastEntryAndFeaturesGoBeforeIt) {
  FilterState s = clonesAtRest(2);
  const int before = s.dim();
  s.addSceneDepth(0.8, 0.09);
  ASSERT_EQ(s.dim(), before + 1);
  EXPECT_EQ(s.sceneDepthIndex(), before);
  EXPECT_DOUBLE_EQ(s.P(before, before), 0.09);
  EXPECT_TRUE(s.P.row(before).head(before).isZero(0.0));
  EXPECT_THROW(s.addSceneDepth(0.5, 0.01), Error);

  addSlamFeatureWithPrior(s, 7, 1, Vec2(0.1, 0.2), 1.0, 0.5, 0.01, Mat2::Identity());
  ASSERT_EQ(s.dim(), before + 4);
  EXPECT_EQ(s.featureIndex(0), before);         // the feature took ρ_s's old place
  EXPECT_EQ(s.sceneDepthIndex(), before + 3);   // ρ_s is still last, its variance carried
  EXPECT_DOUBLE_EQ(s.P(before + 3, before + 3), 0.09);
  EXPECT_DOUBLE_EQ(s.P(before + 2, before + 2), 0.25);

  // correct() moves ρ_s by its own entry; minus() gives that entry back.
  const FilterState ref = s;
  VecX dx = VecX::Zero(s.dim());
  dx(s.sceneDepthIndex()) = 0.05;
  dx(s.featureIndex(0) + 2) = -0.1;
  s.correct(dx);
  EXPECT_DOUBLE_EQ(s.scene_rho, 0.85);
  EXPECT_DOUBLE_EQ(s.features[0].abr.z(), 0.9);
  EXPECT_LT((s.minus(ref) - dx).cwiseAbs().maxCoeff(), 1e-15);
  // ρ_s lies outside the unobservable yaw direction.
  EXPECT_EQ(s.yawDirection(s.imu)(s.sceneDepthIndex()), 0.0);
}

TEST(SceneDepthState, ClonesAndFeaturesComeAndGoAroundTheSceneDepth) {
  // A clone added, the oldest removed, the feature re-anchored and removed:
  // ρ_s stays the last entry with its variance, and its covariance with the
  // feature follows the feature.
  FilterState s = clonesAtRest(2);
  s.clones[1].p_W_C = s.clones[1].p_fej = Vec3(0.2, 0.0, 0.0);
  s.addSceneDepth(0.8, 0.09);
  addSlamFeatureFromSceneDepth(s, 5, 0, Vec2(0.1, -0.05), 0.2, 0.01, Mat2::Identity());
  const double P_ss = s.P(s.sceneDepthIndex(), s.sceneDepthIndex());
  EXPECT_NEAR(s.P(s.featureIndex(0) + 2, s.sceneDepthIndex()), 0.09, 1e-15);

  Eigen::Matrix<double, kCloneDim, Eigen::Dynamic> J = Eigen::Matrix<double, kCloneDim, Eigen::Dynamic>::Zero(6, s.dim());
  J.block<3, 3>(0, kIdxP).setIdentity();
  J.block<3, 3>(3, kIdxTheta).setIdentity();
  CameraClone c;
  c.id = 7;
  s.addClone(c, J);
  ASSERT_EQ(s.clones.size(), 3u);
  EXPECT_EQ(s.sceneDepthIndex(), s.dim() - 1);
  EXPECT_EQ(s.P(s.sceneDepthIndex(), s.sceneDepthIndex()), P_ss);
  EXPECT_NEAR(s.P(s.featureIndex(0) + 2, s.sceneDepthIndex()), 0.09, 1e-15);
  EXPECT_TRUE(s.P.block(s.cloneIndex(2), s.sceneDepthIndex(), 6, 1).isZero(0.0));  // the IMU's cov with ρ_s

  ASSERT_TRUE(reanchorSlamFeature(s, 0, 1));  // the anchor moves 0.2 m: ρ' = ρ / h_z, so cov(ρ', ρ_s) = ∂ρ'/∂f cov(f, ρ_s)
  EXPECT_EQ(s.P(s.sceneDepthIndex(), s.sceneDepthIndex()), P_ss);
  EXPECT_GT(s.P(s.featureIndex(0) + 2, s.sceneDepthIndex()), 0.0);
  s.removeClone(0);
  EXPECT_EQ(s.sceneDepthIndex(), s.dim() - 1);
  EXPECT_EQ(s.P(s.sceneDepthIndex(), s.sceneDepthIndex()), P_ss);
  s.removeFeature(0);
  EXPECT_EQ(s.dim(), 15 + 12 + 1);
  EXPECT_EQ(s.P(s.sceneDepthIndex(), s.sceneDepthIndex()), P_ss);
  EXPECT_DOUBLE_EQ(s.scene_rho, 0.8);
}

TEST(SceneDepthState, OneFeaturesDepthMeasurementMovesTheSceneAndEveryFeatureThatSharesIt) {
  // ρ_s ~ N(1, c σ²), ρ_i = ρ_s + δ_i with δ_i ~ N(0, (1 − c) σ²); a direct
  // measurement y = ρ_1 + v, v ~ N(0, r). Exact Gaussian conditioning:
  //   gain on ρ_1: σ²/(σ² + r);  on ρ_s and on ρ_2: c σ²/(σ² + r);
  //   cov(ρ_s, ρ_2) after = c σ² − (c σ²)²/(σ² + r).
  const double c = 0.8, sigma = 0.5, r = 0.01, y = 0.4;
  const double s2 = sigma * sigma;
  FilterState s = clonesAtRest(1);
  s.addSceneDepth(1.0, c * s2);
  const double sd = std::sqrt(1.0 - c) * sigma;
  addSlamFeatureFromSceneDepth(s, 1, 0, Vec2(0.1, 0.0), sd, 0.01, Mat2::Identity());
  addSlamFeatureFromSceneDepth(s, 2, 0, Vec2(-0.1, 0.0), sd, 0.01, Mat2::Identity());
  const int r1 = s.featureIndex(0) + 2, r2 = s.featureIndex(1) + 2, rs = s.sceneDepthIndex();
  EXPECT_NEAR(s.P(r1, r1), s2, 1e-15);       // the first feature's marginal is the fixed prior's
  EXPECT_NEAR(s.P(r1, r2), c * s2, 1e-15);   // the shared part
  EXPECT_NEAR(s.P(r1, rs), c * s2, 1e-15);
  EXPECT_DOUBLE_EQ(s.features[1].abr.z(), 1.0);
  EXPECT_TRUE(s.P.row(r1).head(s.featureIndex(0)).isZero(0.0));  // the clone's error is not the depth's

  MatX H = MatX::Zero(1, s.dim());
  H(0, r1) = 1.0;
  VecX res(1);
  res(0) = y - s.features[0].abr.z();
  ASSERT_TRUE(ekfUpdate(s, H, res, r, true));
  const double k1 = s2 / (s2 + r), ks = c * s2 / (s2 + r);
  EXPECT_NEAR(s.features[0].abr.z(), 1.0 + k1 * (y - 1.0), 1e-12);
  EXPECT_NEAR(s.scene_rho, 1.0 + ks * (y - 1.0), 1e-12);
  EXPECT_NEAR(s.features[1].abr.z(), 1.0 + ks * (y - 1.0), 1e-12);
  const double cov_s2 = c * s2 - (c * s2) * (c * s2) / (s2 + r);
  EXPECT_NEAR(s.P(rs, r2), cov_s2, 1e-12);

  // A feature initialised now starts from the posterior of ρ_s.
  const double P_ss = s.P(rs, rs);
  EXPECT_NEAR(P_ss, cov_s2, 1e-12);  // ρ_s and ρ_2 differ by δ_2, which the measurement did not touch
  addSlamFeatureFromSceneDepth(s, 3, 0, Vec2(0.0, 0.1), sd, 0.01, Mat2::Identity());
  const int r3 = s.featureIndex(2) + 2;
  EXPECT_DOUBLE_EQ(s.features[2].abr.z(), s.scene_rho);
  EXPECT_NEAR(s.P(r3, r3), P_ss + (1.0 - c) * s2, 1e-12);
  EXPECT_NEAR(s.P(r3, r2), cov_s2, 1e-12);
  EXPECT_NEAR(s.P(r3, s.sceneDepthIndex()), P_ss, 1e-12);
}

using Bench = test::UpdaterBench;

TrackMap twoTracksWithoutParallax() {
  TrackMap tracks;
  for (const FeatureId id : {3, 4}) {
    FeatureTrack t;
    t.id = id;
    t.observations = {{0, Vec2(0.1 * id, 0.0)}, {1, Vec2(0.1 * id, 0.0)}};
    tracks[id] = t;
  }
  return tracks;
}

TEST(SceneDepthState, FixedPriorFeaturesShareTheSceneDepthWhenTheShareIsSet) {
  // Two clones at one pose (no parallax, no map): both candidates take the
  // fixed prior ρ0 = 1, σ = 0.5 (d_min = 0.5 m). With share 0.6 the first
  // call adds ρ_s ~ N(1, 0.6 · 0.25) and the two features are correlated by it.
  Bench b(clonesAtRest(2));
  b.options.slam_min_depth_m = 0.5;
  b.options.slam_scene_depth_share = 0.6;
  b.options.slam_scene_depth_memory_s = 4.0;
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks = twoTracksWithoutParallax();
  ASSERT_TRUE(slam.initialize({3, 4}, &tracks));
  ASSERT_TRUE(b.state.has_scene_depth);
  ASSERT_EQ(b.state.features.size(), 2u);
  EXPECT_EQ(b.stats.slam_initialized_prior, 2);
  const int r3 = b.state.featureIndex(0) + 2, r4 = b.state.featureIndex(1) + 2, rs = b.state.sceneDepthIndex();
  EXPECT_DOUBLE_EQ(b.state.features[0].abr.z(), 1.0);
  EXPECT_NEAR(b.state.P(r3, r3), 0.25, 1e-15);
  EXPECT_NEAR(b.state.P(r4, r4), 0.25, 1e-15);
  EXPECT_NEAR(b.state.P(r3, r4), 0.15, 1e-15);
  EXPECT_NEAR(b.state.P(rs, rs), 0.15, 1e-15);

  // The random walk: over 2 s of a 4 s memory, half the shared variance again.
  slam.diffuseSceneDepth(2.0);
  EXPECT_NEAR(b.state.P(rs, rs), 0.15 + 0.075, 1e-15);
  EXPECT_NEAR(b.state.P(r3, r4), 0.15, 1e-15);  // the features keep what they shared

  // Off (the default): independent priors and no scene depth in the state.
  Bench off(clonesAtRest(2));
  off.options.slam_min_depth_m = 0.5;
  SlamUpdater plain(off.context(), kCamera, 0.01, &off.chi2, &off.chi2, nullptr);
  TrackMap t2 = twoTracksWithoutParallax();
  ASSERT_TRUE(plain.initialize({3, 4}, &t2));
  EXPECT_FALSE(off.state.has_scene_depth);
  EXPECT_EQ(off.state.P(off.state.featureIndex(0) + 2, off.state.featureIndex(1) + 2), 0.0);
  plain.diffuseSceneDepth(2.0);  // nothing to diffuse
  EXPECT_EQ(off.state.dim(), 15 + 12 + 6);
}

TEST(SceneDepthState, TheFirstTriangulatedPointsMeasureTheSceneDepthOnce) {
  // ρ_s ~ N(1, 0.225) and one feature from it; then three triangulated points
  // 2, 2.5 and 4 m ahead: the median 1/2.5 = 0.4 measures ρ_s with σ 0.2, so
  //   ρ_s ← 1 + K (0.4 − 1), K = 0.225 / (0.225 + 0.04),
  // and the feature, which shares all of ρ_s's variance, moves with it.
  Bench b(clonesAtRest(2));
  b.options.slam_min_depth_m = 0.5;
  b.options.slam_scene_depth_share = 0.9;
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks = twoTracksWithoutParallax();
  ASSERT_TRUE(slam.initialize({3}, &tracks));  // no points yet: nothing measured
  EXPECT_DOUBLE_EQ(b.state.scene_rho, 1.0);
  EXPECT_EQ(b.stats.slam_scene_depth_measured, 0);
  for (const double z : {2.0, 2.5, 4.0}) b.triangulated.add(Vec3(0.3, -0.2, z));
  ASSERT_TRUE(slam.initialize({}, &tracks));
  const double K = 0.225 / (0.225 + 0.04);
  EXPECT_NEAR(b.state.scene_rho, 1.0 + K * (0.4 - 1.0), 1e-12);
  EXPECT_NEAR(b.state.features[0].abr.z(), 1.0 + K * (0.4 - 1.0), 1e-12);
  EXPECT_NEAR(b.state.P(b.state.sceneDepthIndex(), b.state.sceneDepthIndex()), 0.225 * (1.0 - K), 1e-12);
  EXPECT_EQ(b.stats.slam_scene_depth_measured, 1);
  const double after = b.state.scene_rho;
  ASSERT_TRUE(slam.initialize({}, &tracks));  // once only: the same points are not evidence again
  EXPECT_EQ(b.state.scene_rho, after);
  EXPECT_EQ(b.stats.slam_scene_depth_measured, 1);
}

TEST(SceneDepthState, AFeatureBehindTheSceneTakesThePlainPrior) {
  // ρ_s driven to a negative value (a scene behind the camera): new features
  // take the independent fixed prior instead.
  Bench b(clonesAtRest(2));
  b.options.slam_min_depth_m = 0.5;
  b.options.slam_scene_depth_share = 0.5;
  b.state.addSceneDepth(-0.2, 0.01);
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks = twoTracksWithoutParallax();
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  ASSERT_EQ(b.state.features.size(), 1u);
  const int r3 = b.state.featureIndex(0) + 2;
  EXPECT_DOUBLE_EQ(b.state.features[0].abr.z(), 1.0);
  EXPECT_EQ(b.state.P(r3, b.state.sceneDepthIndex()), 0.0);
  EXPECT_NEAR(b.state.P(r3, r3), 0.25, 1e-15);
}

TEST(SceneDepthState, OptionsAreChecked) {
  BackendOptions o;
  o.slam_scene_depth_share = 1.0;
  EXPECT_THROW(o.validate(), Error);
  o.slam_scene_depth_share = -0.1;
  EXPECT_THROW(o.validate(), Error);
  o.slam_scene_depth_share = 0.5;
  o.slam_scene_depth_memory_s = 0.0;
  EXPECT_THROW(o.validate(), Error);
  o.slam_scene_depth_memory_s = 10.0;
  EXPECT_NO_THROW(o.validate());
}

TEST(BackendOptions, IteratedMsckfRowsNeedTheSlamRowsLinearisedOnce) {
  BackendOptions o;
  o.msckf_iterations = 3;
  EXPECT_NO_THROW(o.validate());
  o.iekf_iterations = 2;
  EXPECT_THROW(o.validate(), Error);
  o.msckf_iterations = 0;
  o.iekf_iterations = 1;
  EXPECT_THROW(o.validate(), Error);
}

}  // namespace
}  // namespace evio::estimator

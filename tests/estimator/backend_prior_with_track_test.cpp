// A depth prior taken together with the track's observations
// (BackendOptions::slam_prior_init_with_track; triangulation.h
// refineWithDepthPrior, slam_features.h addSlamFeatureTriangulated with a
// prior row): the MAP answer against its own cost, the two limits (no
// parallax: the prior; no prior weight: the point), and the split; and the
// variant that takes the plain prior and then the track as an update
// (slam_prior_track_update): one EKF update of the earlier observations, or
// iterated, the joint MAP of clones, feature and prior, checked against that
// cost written out in the test.
#include <gtest/gtest.h>

#include <cmath>

#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/slam_updater.h"
#include "evio/estimator/backend/triangulation.h"
#include "evio/estimator/backend/visual_models.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));

/// n clones looking along +z of W, at x = baseline · i (m).
std::vector<CameraClone> clonesAlongX(int n, double baseline) {
  std::vector<CameraClone> out;
  for (int i = 0; i < n; ++i) {
    CameraClone c;
    c.id = i;
    c.p_W_C = c.p_fej = Vec3(baseline * i, 0.0, 0.0);
    out.push_back(c);
  }
  return out;
}

/// A state holding `clones`, P = 1e-6 I.
FilterState stateOf(const std::vector<CameraClone>& clones) {
  FilterState s;
  s.clones = clones;
  s.P = 1e-6 * MatX::Identity(s.dim(), s.dim());
  return s;
}

std::vector<Vec2> observe(const std::vector<CameraClone>& clones, const Vec3& p_W, const std::vector<Vec2>& noise) {
  std::vector<Vec2> z;
  for (std::size_t i = 0; i < clones.size(); ++i) {
    Vec2 zi;
    EXPECT_TRUE(projectWorldPoint(clones[i], p_W, &zi));
    z.push_back(zi + noise[i % noise.size()]);
  }
  return z;
}

/// The MAP cost, written out on its own: Σ‖W(z − ẑ)‖² + (σ_z/σ_ρ0)² (ρ − ρ0)².
double mapCost(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z, const Vec3& abr, double rho0,
               double sigma_rho0, double sigma_z) {
  double cost = 0.0;
  for (std::size_t i = 0; i < clones.size(); ++i) {
    Vec2 zh;
    if (!projectAnchoredFeature(clones.back(), clones[i], abr, &zh)) return 1e300;
    cost += (z[i] - zh).squaredNorm();
  }
  const double w = sigma_z / sigma_rho0;
  return cost + w * w * (abr.z() - rho0) * (abr.z() - rho0);
}

TEST(PriorWithTrack, WithoutParallaxTheAnswerIsThePrior) {
  const std::vector<CameraClone> clones = clonesAlongX(6, 0.0);
  const std::vector<Vec2> z = observe(clones, Vec3(0.3, -0.2, 4.0), {Vec2(0.001, -0.002), Vec2(-0.001, 0.0)});
  const std::vector<Mat2> W(clones.size(), Mat2::Identity());
  Vec3 abr;
  ASSERT_TRUE(refineWithDepthPrior(clones, z, W, clones.size() - 1, 1.0, 0.5, 0.01, TriangulationOptions{}, &abr));
  EXPECT_NEAR(abr.z(), 1.0, 1e-12);  // the data do not see ρ at all
  // (α, β): the mean of the bearings, which is where Σ‖z_i − (α, β)‖² is least.
  Vec2 mean = Vec2::Zero();
  for (const Vec2& zi : z) mean += zi / static_cast<double>(z.size());
  EXPECT_LT((abr.head<2>() - mean).norm(), 1e-12);
}

TEST(PriorWithTrack, WithParallaxAndAWeakPriorTheAnswerIsThePoint) {
  // A point 4 m away (ρ = 0.25) seen over 0.6 m of baseline without noise;
  // a prior at ρ0 = 1 with σ 1e4 weighs nothing.
  const std::vector<CameraClone> clones = clonesAlongX(7, 0.1);
  const Vec3 p_W(0.3, -0.2, 4.0);
  const std::vector<Vec2> z = observe(clones, p_W, {Vec2::Zero()});
  const std::vector<Mat2> W(clones.size(), Mat2::Identity());
  Vec3 abr;
  ASSERT_TRUE(refineWithDepthPrior(clones, z, W, clones.size() - 1, 1.0, 1e4, 0.01, TriangulationOptions{}, &abr));
  EXPECT_LT((anchoredToWorld(clones.back(), abr) - p_W).norm(), 1e-6);
}

TEST(PriorWithTrack, TheAnswerIsTheLeastOfTheMapCost) {
  // Noisy observations over a short baseline and the prior 1.5 σ from the
  // truth: the answer lies between them, and no nearby point costs less.
  const std::vector<CameraClone> clones = clonesAlongX(10, 0.01);
  const std::vector<Vec2> z =
      observe(clones, Vec3(0.3, -0.2, 4.0), {Vec2(0.004, -0.002), Vec2(-0.003, 0.001), Vec2(0.0, 0.005)});
  const std::vector<Mat2> W(clones.size(), Mat2::Identity());
  const double rho0 = 1.0, sigma0 = 0.5, sigma_z = 0.025;
  TriangulationOptions opt;
  opt.max_iterations = 50;
  opt.tolerance = 1e-12;
  Vec3 abr;
  ASSERT_TRUE(refineWithDepthPrior(clones, z, W, clones.size() - 1, rho0, sigma0, sigma_z, opt, &abr));
  EXPECT_GT(abr.z(), 0.0);
  EXPECT_LT(abr.z(), 0.9);  // the data pulled it from the prior towards 0.25
  const double best = mapCost(clones, z, abr, rho0, sigma0, sigma_z);
  for (int k = 0; k < 3; ++k) {
    for (const double h : {-1e-4, 1e-4}) {
      Vec3 x = abr;
      x(k) += h;
      EXPECT_GE(mapCost(clones, z, x, rho0, sigma0, sigma_z), best) << k << " " << h;
    }
  }
}

TEST(PriorWithTrack, TheSplitWithoutParallaxGivesThePriorsDepthAndUsesEveryBearing) {
  // Clones at one pose: the observations say nothing about ρ, so the
  // feature's ρ has the prior's mean and variance and no correlation with
  // the clones; (α, β) are fixed by all observations.
  FilterState s = stateOf(clonesAlongX(5, 0.0));
  FeatureTrack track;
  track.id = 9;
  for (const CameraClone& c : s.clones) track.observations.push_back({c.id, Vec2(0.1, 0.05)});
  const InverseDepthPrior prior{0.8, 0.4};
  const double sigma_z = 0.01;
  const auto outcome = addSlamFeatureTriangulated(
      s, track, Vec3(0.1, 0.05, 0.8), sigma_z * sigma_z, true, [](int) { return 1e9; }, [](MatX*) {}, &prior);
  ASSERT_EQ(outcome, SlamInitOutcome::kOk);
  ASSERT_EQ(s.features.size(), 1u);
  const int k = s.featureIndex(0);
  EXPECT_NEAR(s.features[0].abr.z(), 0.8, 1e-12);
  EXPECT_NEAR(s.P(k + 2, k + 2), 0.4 * 0.4, 1e-12);
  EXPECT_LT(s.P.row(k + 2).head(k).cwiseAbs().maxCoeff(), 1e-15);
  // Five observations of one bearing: its variance below one observation's.
  EXPECT_LT(s.P(k, k), sigma_z * sigma_z);
}

using Bench = test::UpdaterBench;

TEST(PriorWithTrack, TheSlamUpdaterTakesThePriorWithTheTrackWhenAsked) {
  for (const bool with_track : {false, true}) {
    FilterState s = stateOf(clonesAlongX(4, 0.0));
    Bench b(s);
    b.options.slam_min_depth_m = 0.5;
    b.options.slam_prior_init_with_track = with_track;
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    FeatureTrack t;
    t.id = 3;
    for (const CameraClone& c : b.state.clones) t.observations.push_back({c.id, Vec2(0.2, 0.1)});
    TrackMap tracks{{3, t}};
    ASSERT_TRUE(slam.initialize({3}, &tracks));
    ASSERT_EQ(b.state.features.size(), 1u);
    EXPECT_NEAR(b.state.features[0].abr.z(), 1.0, 1e-12) << with_track;
    EXPECT_EQ(b.stats.slam_initialized_prior_track, with_track ? 1 : 0);
    EXPECT_EQ(b.stats.slam_initialized_prior, with_track ? 0 : 1);
    EXPECT_TRUE(tracks.empty());
  }
}

TEST(PriorWithTrack, BelowTheParallaxThresholdThePriorIsTakenAlone) {
  // A point 4 m away over a 0.3 m baseline (4 clones 0.1 m apart): about
  // 7.5 px of rotation-compensated disparity at f = 100 px.
  const Vec3 p_W(0.3, -0.2, 4.0);
  auto run = [&](double min_parallax_px, BackendStats* stats, MatX* clone_P) {
    FilterState s = stateOf(clonesAlongX(4, 0.1));
    Bench b(s);
    b.options.slam_min_depth_m = 0.5;
    b.options.slam_triangulated_init = false;
    b.options.slam_prior_init_with_track = true;
    b.options.slam_prior_track_min_parallax_px = min_parallax_px;
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    FeatureTrack t;
    t.id = 3;
    const std::vector<Vec2> z = observe(b.state.clones, p_W, {Vec2::Zero()});
    for (std::size_t i = 0; i < z.size(); ++i) t.observations.push_back({b.state.clones[i].id, z[i]});
    TrackMap tracks{{3, t}};
    EXPECT_TRUE(slam.initialize({3}, &tracks));
    *stats = b.stats;
    *clone_P = b.state.P.block(15, 15, 24, 24);
    return b.state.features.at(0).abr.z();
  };
  BackendStats stats;
  MatX clone_P;
  // Above the threshold: the track moves ρ from the prior's 1 towards 0.25.
  EXPECT_LT(run(5.0, &stats, &clone_P), 0.5);
  EXPECT_EQ(stats.slam_initialized_prior_track, 1);
  EXPECT_LT(clone_P.trace(), 24e-6);  // the remaining rows updated the clones
  // Below it (10 px asked): the plain prior.
  EXPECT_DOUBLE_EQ(run(10.0, &stats, &clone_P), 1.0);
  EXPECT_EQ(stats.slam_initialized_prior, 1);
  EXPECT_EQ(stats.slam_initialized_prior_track, 0);
  EXPECT_TRUE(clone_P.isApprox(1e-6 * MatX::Identity(24, 24), 1e-15));  // no update of the clones
}

/// Options for the track as an update after the plain prior: ρ0 = 1 (σ 0.5)
/// from d_min = 0.5 m, no triangulated initialisation.
void useTrackUpdate(BackendOptions* o, int iterations) {
  o->slam_min_depth_m = 0.5;
  o->slam_triangulated_init = false;
  o->slam_prior_init_with_track = true;
  o->slam_prior_track_update = true;
  o->slam_prior_track_iterations = iterations;
}

/// Track `id` observed at z[i] from clones[i], whitened by W.
FeatureTrack trackOf(FeatureId id, const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                     const Mat2& W = Mat2::Identity()) {
  FeatureTrack t;
  t.id = id;
  for (std::size_t i = 0; i < z.size(); ++i) t.observations.push_back({clones[i].id, z[i], W});
  return t;
}

/// The joint cost the iterated initialisation minimises, written out:
/// ‖x ⊟ x0‖² in the metric of the prior covariance P0 (the state before the
/// update, with the new feature at its plain prior) plus the track's earlier
/// observations Σ_k ‖z_k − h(clone_k, f)‖² / σ_z².
double jointCost(const FilterState& x, const FilterState& x0, const MatX& P0_inv, const std::vector<Vec2>& z,
                 double sigma_z) {
  const VecX d = x.minus(x0);
  double cost = d.dot(P0_inv * d);
  const std::size_t anchor = x.clones.size() - 1;
  for (std::size_t k = 0; k + 1 < z.size(); ++k) {
    Vec2 zh;
    if (!projectAnchoredFeature(x.clones[anchor], x.clones[k], x.features[0].abr, &zh)) return 1e300;
    cost += (z[k] - zh).squaredNorm() / (sigma_z * sigma_z);
  }
  return cost;
}

TEST(PriorWithTrack, TheIteratedUpdateIsTheMapOfClonesFeatureAndPrior) {
  // Six clones 2 cm apart with 1 cm of position uncertainty, a point 4 m
  // away (ρ = 0.25), noisy observations, and the prior ρ0 = 1 (σ 0.5): the
  // update moves clones and feature together to the least of the joint cost.
  const std::vector<CameraClone> clones = clonesAlongX(6, 0.02);
  FilterState s = stateOf(clones);
  s.P = 1e-4 * MatX::Identity(s.dim(), s.dim());
  Bench b(s);
  useTrackUpdate(&b.options, 30);
  b.options.observability_constraint = false;  // the plain MAP, no projected directions
  const double sigma_z = 0.01;
  SlamUpdater slam(b.context(), kCamera, sigma_z, &b.chi2, &b.chi2, nullptr);
  const std::vector<Vec2> z = observe(clones, Vec3(0.3, -0.2, 4.0),
                                      {Vec2(0.004, -0.002), Vec2(-0.003, 0.001), Vec2(0.0, 0.005)});
  const FeatureTrack t = trackOf(3, clones, z);
  // The prior: the state with the feature at its plain prior.
  FilterState x0 = s;
  addSlamFeatureWithPrior(x0, 3, clones.size() - 1, z.back(), 1.0, 0.5, sigma_z);
  const MatX P0_inv = x0.P.inverse();
  TrackMap tracks{{3, t}};
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  EXPECT_EQ(b.stats.slam_initialized_prior_track, 1);
  ASSERT_EQ(b.state.features.size(), 1u);
  const FilterState& x = b.state;
  EXPECT_LT(x.features[0].abr.z(), 0.9);  // pulled from the prior towards 0.25
  EXPECT_GT(x.clones[0].p_W_C.norm(), 1e-6);  // the clones moved too
  const double best = jointCost(x, x0, P0_inv, z, sigma_z);
  // No neighbour in any direction of the state costs less (relative step 1e-4 of each σ).
  for (int i = 0; i < x.dim(); ++i) {
    for (const double sign : {-1.0, 1.0}) {
      FilterState y = x;
      VecX dx = VecX::Zero(x.dim());
      dx(i) = sign * 1e-4 * std::sqrt(x0.P(i, i));
      y.correct(dx);
      EXPECT_GE(jointCost(y, x0, P0_inv, z, sigma_z), best - 1e-9) << i << " " << sign;
    }
  }
}

TEST(PriorWithTrack, OneIterationIsTheEkfUpdateOfTheEarlierObservationsAtThePlainPrior) {
  for (const bool constrained : {false, true}) {
    const std::vector<CameraClone> clones = clonesAlongX(6, 0.02);
    FilterState s = stateOf(clones);
    s.P = 1e-4 * MatX::Identity(s.dim(), s.dim());
    Bench b(s);
    useTrackUpdate(&b.options, 1);
    b.options.observability_constraint = constrained;
    const double sigma_z = 0.01;
    SlamUpdater slam(b.context(), kCamera, sigma_z, &b.chi2, &b.chi2, nullptr);
    const std::vector<Vec2> z = observe(clones, Vec3(0.3, -0.2, 4.0), {Vec2(0.004, -0.002), Vec2(-0.003, 0.001)});
    // Whitening that is not the identity (EKLT's per-point covariance).
    const Mat2 W = (Mat2() << 1.2, 0.3, 0.0, 0.8).finished();
    const FeatureTrack t = trackOf(3, clones, z, W);
    // By hand: the plain prior at the last observation, then the whitened
    // rows of the five earlier observations stacked (projected off the yaw
    // direction n when constrained), one EKF update.
    FilterState expected = s;
    addSlamFeatureWithPrior(expected, 3, clones.size() - 1, z.back(), 1.0, 0.5, sigma_z, W);
    MatX H = MatX::Zero(10, expected.dim());
    VecX r(10);
    for (std::size_t k = 0; k < 5; ++k) {
      Eigen::Matrix<double, 2, Eigen::Dynamic> Hk;
      Vec2 rk;
      ASSERT_TRUE(slamResidual(expected, 0, k, z[k], &Hk, &rk));
      H.middleRows<2>(2 * static_cast<Eigen::Index>(k)) = W * Hk;
      r.segment<2>(2 * static_cast<Eigen::Index>(k)) = W * rk;
    }
    if (constrained) {
      const VecX n = expected.yawDirection(b.fej);
      H -= (H * n) * (n.transpose() / n.squaredNorm());
    }
    ASSERT_TRUE(ekfUpdate(expected, H, r, sigma_z * sigma_z, b.options.joseph_form));
    TrackMap tracks{{3, t}};
    ASSERT_TRUE(slam.initialize({3}, &tracks));
    ASSERT_EQ(b.state.features.size(), 1u);
    EXPECT_EQ(b.stats.slam_initialized_prior_track, 1);
    EXPECT_LT(b.state.minus(expected).norm(), 1e-12) << constrained;
    EXPECT_LT((b.state.P - expected.P).cwiseAbs().maxCoeff(), 1e-15) << constrained;
  }
}

/// Initialises track 3 (observations z from `clones`, P = 1e-6 I) with the
/// track update and expects the plain prior alone: ρ = ρ0, the clones untouched.
void expectThePlainPriorAlone(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z) {
  Bench b(stateOf(clones));
  useTrackUpdate(&b.options, 1);
  SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
  TrackMap tracks{{3, trackOf(3, clones, z)}};
  ASSERT_TRUE(slam.initialize({3}, &tracks));
  EXPECT_EQ(b.stats.slam_initialized_prior_track, 0);
  EXPECT_EQ(b.stats.slam_initialized_prior, 1);
  ASSERT_EQ(b.state.features.size(), 1u);
  EXPECT_DOUBLE_EQ(b.state.features[0].abr.z(), 1.0);
  const int n = 6 * static_cast<int>(clones.size());
  EXPECT_TRUE(b.state.P.block(15, 15, n, n).isApprox(1e-6 * MatX::Identity(n, n), 1e-15));
}

TEST(PriorWithTrack, TheUpdateLeavesThePlainPriorWhenAnEarlierObservationCannotBePredicted) {
  std::vector<CameraClone> clones = clonesAlongX(5, 0.02);
  const std::vector<Vec2> z = observe(clones, Vec3(0.3, -0.2, 4.0), {Vec2::Zero()});
  clones[1].q_W_C = clones[1].q_fej = Quat(Eigen::AngleAxisd(M_PI, Vec3::UnitY()));  // looks away: the point is behind it
  expectThePlainPriorAlone(clones, z);
}

TEST(PriorWithTrack, TheUpdateLeavesThePlainPriorWhenTheTrackFailsTheGate) {
  const std::vector<CameraClone> clones = clonesAlongX(5, 0.02);
  std::vector<Vec2> z = observe(clones, Vec3(0.3, -0.2, 4.0), {Vec2::Zero()});
  z[1] += Vec2(0.2, 0.0);  // 20 σ off: an outlier
  expectThePlainPriorAlone(clones, z);
}

}  // namespace
}  // namespace evio::estimator

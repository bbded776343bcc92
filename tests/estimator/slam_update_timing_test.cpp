// When a SLAM feature's observation enters the update and with what weight:
// spacing in time and in image motion, and the weighting by the effective
// number of samples of a correlated track error (docs/algorithms.md
// "Correlated measurements"), each against exact clone times and positions.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/slam_updater.h"
#include "updater_bench.h"

namespace evio::estimator {
namespace {

const Camera kCamera = Camera(PinholeCamera(200, 100, Vec4(100, 100, 100, 50)));

using test::restingState;
using test::UpdaterBench;

/// Clones at the origin at times t_s and one SLAM feature, id 9, (α, β, ρ) =
/// (0.1, −0.2, 0.5) anchored in clone 0 and last updated at t = 0; P = 1e-4 I.
UpdaterBench timedSlamBench(const std::vector<double>& t_s) {
  UpdaterBench b(restingState(static_cast<int>(t_s.size())));
  for (std::size_t i = 0; i < t_s.size(); ++i) b.state.clones[i].t_ns = secondsToNs(t_s[i]);
  SlamFeature f;
  f.id = 9;
  f.anchor_clone_id = 0;
  f.abr = Vec3(0.1, -0.2, 0.5);
  f.last_update_ns = 0;
  b.state.features.push_back(f);
  b.state.P = 1e-4 * MatX::Identity(b.state.dim(), b.state.dim());
  return b;
}

TEST(BackendUpdaters, SlamUpdateIntervalLeavesOutObservationsTooSoonAfterTheLastUpdate) {
  // One feature, initialised at clone 0 (t = 0), observed exactly in clones
  // at 10, 30, 50, 60 and 90 ms. With a 40 ms interval only the observations
  // at 50 ms (40 ms after the initialisation) and 90 ms (40 ms after that
  // update) enter; the others are neither accepted nor counted as rejected.
  const std::vector<double> t_s{0.0, 0.010, 0.030, 0.050, 0.060, 0.090};
  UpdaterBench b = timedSlamBench(t_s);
  const std::vector<FeatureObservation> seen{{9, Vec2(0.1, -0.2)}};
  const auto accepted_at = [&](double interval_s) {
    b.options.slam_update_interval_s = interval_s;
    b.state.features[0].last_update_ns = 0;
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    std::vector<double> at;
    for (std::size_t c = 1; c < t_s.size(); ++c) {
      const SlamGate g = slam.gate(seen, c);
      EXPECT_TRUE(g.gated_out.empty());
      if (!g.accepted.empty()) at.push_back(t_s[c]);
    }
    return at;
  };
  EXPECT_EQ(accepted_at(0.0), (std::vector<double>{0.010, 0.030, 0.050, 0.060, 0.090}));
  EXPECT_EQ(accepted_at(0.04), (std::vector<double>{0.050, 0.090}));
  EXPECT_EQ(b.state.features[0].last_update_ns, secondsToNs(0.090));
  EXPECT_EQ(b.stats.slam_updates_rejected, 0);
  EXPECT_EQ(b.state.features[0].gate_failures, 0);
}

TEST(BackendUpdaters, SlamUpdateDisplacementLetsInObservationsOfAFeatureThatHasMoved) {
  // The feature initialised at t = 0 at z0 = (0.1, −0.2), observed at 10, 30,
  // 50, 60 and 90 ms displaced along x from z0 by 0.006, 0.007, 0.008, 0.014
  // and 0.015 (all inside the gate: σ 0.01). With a least displacement of
  // 0.005 an observation enters when it lies 0.005 or more from the one of
  // the last update: 10 ms (0.006 from z0) and 60 ms (0.006 from 10 ms's);
  // with a 40 ms interval as well, either lets it in: 50 ms too (40 ms
  // after 10 ms's update), and 90 ms is 30 ms and 0.001 after 60 ms's.
  const std::vector<double> t_s{0.0, 0.010, 0.030, 0.050, 0.060, 0.090};
  const std::vector<double> dx{0.0, 0.006, 0.007, 0.008, 0.014, 0.015};
  UpdaterBench b = timedSlamBench(t_s);
  const Vec2 z0(0.1, -0.2);
  const auto accepted_at = [&](double interval_s, double displacement) {
    b.options.slam_update_interval_s = interval_s;
    b.options.slam_update_min_displacement_normalized = displacement;
    b.state.features[0].last_update_ns = 0;
    b.state.features[0].last_update_z = z0;
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    std::vector<double> at;
    for (std::size_t c = 1; c < t_s.size(); ++c) {
      const SlamGate g = slam.gate({{9, z0 + Vec2(dx[c], 0.0)}}, c);
      EXPECT_TRUE(g.gated_out.empty());
      if (!g.accepted.empty()) at.push_back(t_s[c]);
    }
    return at;
  };
  EXPECT_EQ(accepted_at(0.0, 0.005), (std::vector<double>{0.010, 0.060}));
  EXPECT_TRUE(b.state.features[0].last_update_z.isApprox(z0 + Vec2(0.014, 0.0)));
  EXPECT_EQ(accepted_at(0.04, 0.005), (std::vector<double>{0.010, 0.050, 0.060}));
  EXPECT_EQ(accepted_at(0.04, 0.0), (std::vector<double>{0.050, 0.090}));
  EXPECT_EQ(b.stats.slam_updates_rejected, 0);
}

TEST(SlamFeatures, CorrelatedSampleFactorIsTheVarianceOfTheMeanOfFirstOrderMarkovSamples) {
  // N samples Δt apart of an error with covariance σ² ρ^|i−j|, ρ = e^(−Δt/τ):
  // the variance of their mean, summed entry by entry, against κσ²/N with
  // κ = coth(Δt/2τ). The sum's end effect is −2ρ(1 − ρ^N)/(N (1 − ρ)²) of κ,
  // so with N = 20 000 and ρ ≤ 0.9 the two agree to 1e-3 relative.
  const double tau = 0.02;
  for (const double dt : {0.002, 0.0077, 0.02, 0.1}) {
    const double rho = std::exp(-dt / tau);
    const int n = 20000;
    double sum = 0.0;  // Σ_ij ρ^|i−j| = N + 2 Σ_{k≥1} (N − k) ρ^k
    double rk = 1.0;
    for (int k = 1; k < n; ++k) {
      rk *= rho;
      sum += 2.0 * (n - k) * rk;
    }
    const double var_mean = (n + sum) / (static_cast<double>(n) * n);
    EXPECT_NEAR(correlatedSampleVarianceFactor(dt, tau) / n / var_mean, 1.0, 1e-3) << "dt " << dt;
  }
  EXPECT_NEAR(correlatedSampleVarianceFactor(0.001, 0.05), 2.0 * 0.05 / 0.001, 1e-2);  // ≈ 2τ/Δt, Δt ≪ τ
  EXPECT_NEAR(correlatedSampleVarianceFactor(1.0, 0.01), 1.0, 1e-12);                // independent, Δt ≫ τ
  EXPECT_EQ(correlatedSampleVarianceFactor(0.01, 0.0), 1.0);                          // off
  EXPECT_TRUE(std::isinf(correlatedSampleVarianceFactor(0.0, 0.02)));                 // the same instant
}

TEST(BackendUpdaters, TrackErrorTimeWidensEachSlamObservationByItsEffectiveSampleFactor) {
  // The feature initialised at t = 0, observed exactly at 10, 30 and 60 ms
  // with an anisotropic whitening W. With τ = 20 ms each accepted
  // observation's whitening is W / √coth(Δt/2τ), Δt the time since the last
  // update: 10, 20 and 30 ms; with τ = 0 it is W unchanged.
  const std::vector<double> t_s{0.0, 0.010, 0.030, 0.060};
  UpdaterBench b = timedSlamBench(t_s);
  Mat2 W;
  W << 0.8, 0.1, 0.0, 0.5;
  FeatureObservation seen{9, Vec2(0.1, -0.2), W};
  const auto whitening_at = [&](double tau_s) {
    seen.error_time_s = tau_s;  // as the tracker states it
    b.state.features[0].last_update_ns = 0;
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    std::vector<Mat2> out;
    for (std::size_t c = 1; c < t_s.size(); ++c) {
      const SlamGate g = slam.gate({seen}, c);
      EXPECT_EQ(g.accepted.size(), 1u);
      if (!g.accepted.empty()) out.push_back(g.accepted[0].whiten);
    }
    return out;
  };
  const std::vector<Mat2> off = whitening_at(0.0);
  ASSERT_EQ(off.size(), 3u);
  for (const Mat2& w : off) EXPECT_EQ(w, W);
  const std::vector<Mat2> on = whitening_at(0.02);
  ASSERT_EQ(on.size(), 3u);
  const std::vector<double> dt{0.010, 0.020, 0.030};
  for (std::size_t q = 0; q < dt.size(); ++q) {
    const double kappa = 1.0 / std::tanh(dt[q] / 0.04);
    EXPECT_TRUE(on[q].isApprox(W / std::sqrt(kappa), 1e-12)) << "at " << t_s[q + 1] << " s";
  }
  EXPECT_EQ(b.state.features[0].last_update_ns, secondsToNs(0.060));
}

TEST(BackendUpdaters, TrackErrorTimeLeavesTheSlamGateToTheObservationsOwnCovariance) {
  // An observation 0.06 off the prediction, 10 ms after the last update:
  // the gate rejects it with its own covariance (W), and would pass it with
  // the covariance × κ = coth(10 ms / 40 ms) = 4.08 it enters an update with
  // at τ = 20 ms (W/√κ). With τ = 20 ms the gate still rejects it.
  constexpr double kOffset = 0.06;
  const auto rejected = [](double tau_s, const Mat2& whiten) {
    UpdaterBench b = timedSlamBench({0.0, 0.010});
    SlamUpdater slam(b.context(), kCamera, 0.01, &b.chi2, &b.chi2, nullptr);
    slam.gate({{9, Vec2(0.1 + kOffset, -0.2), whiten, true, tau_s}}, 1);
    return b.stats.slam_updates_rejected == 1;
  };
  const double kappa = 1.0 / std::tanh(0.25);
  EXPECT_TRUE(rejected(0.0, Mat2::Identity()));
  EXPECT_FALSE(rejected(0.0, Mat2::Identity() / std::sqrt(kappa)));
  EXPECT_TRUE(rejected(0.02, Mat2::Identity()));
}

}  // namespace
}  // namespace evio::estimator

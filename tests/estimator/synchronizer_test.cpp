#include "evio/estimator/frontend/synchronizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <utility>
#include <vector>

#include "evio/core/error.h"

namespace evio::estimator {
namespace {

TrackPoint point(FeatureId id, double t_s, Vec2 uv, TrackStatus status = TrackStatus::kTracked) {
  return TrackPoint{id, secondsToNs(t_s), uv, 1.0, status};
}

/// A track moving linearly: uv(t) = uv0 + v t.
Vec2 linear(const Vec2& uv0, const Vec2& v, double t) { return uv0 + v * t; }

/// Options that compensate a lag of τ (s) and a (px), an update every 10
/// events, the velocity over the newest two points (window 0) or window_s.
SynchronizerOptions lagOptions(double tau_s, double a_px, double window_s) {
  SynchronizerOptions o;
  o.n_e = 10;
  o.track_latency_s = tau_s;
  o.track_lag_px = a_px;
  o.velocity_window_s = window_s;
  return o;
}

TEST(Synchronizer, EveryNeEventsExtrapolatesLinearlyToTheLatestTrackTime) {
  SynchronizerOptions o;
  o.n_e = 100;
  Synchronizer sync(o);
  const Vec2 a0(10, 20), va(5, -3), b0(50, 60), vb(-2, 7);
  sync.addTrackPoints({point(1, 0.00, linear(a0, va, 0.00), TrackStatus::kNew), point(2, 0.01, linear(b0, vb, 0.01), TrackStatus::kNew),
                       point(1, 0.02, linear(a0, va, 0.02)), point(2, 0.05, linear(b0, vb, 0.05)),
                       point(1, 0.04, linear(a0, va, 0.04))});
  sync.addEvents(99, secondsToNs(0.05));
  MeasurementSet set;
  EXPECT_FALSE(sync.poll(&set));  // 99 < n_e
  sync.addEvents(1, secondsToNs(0.05));
  ASSERT_TRUE(sync.poll(&set));
  EXPECT_EQ(set.t_ns, secondsToNs(0.05));  // the latest track time
  ASSERT_EQ(set.features.size(), 2u);
  EXPECT_EQ(set.features[0].id, 1);
  EXPECT_LT((set.features[0].uv - linear(a0, va, 0.05)).norm(), 1e-9);  // extrapolated from 0.02, 0.04
  EXPECT_LT((set.features[1].uv - linear(b0, vb, 0.05)).norm(), 1e-9);
  EXPECT_FALSE(set.features[0].has_previous);

  // No track moved: n_e more events give no update.
  sync.addEvents(100, secondsToNs(0.06));
  EXPECT_FALSE(sync.poll(&set));

  // Track 1 moves; the update time 0.07 > 0.05; previous = sent positions.
  sync.addTrackPoints({point(1, 0.07, linear(a0, va, 0.07))});
  sync.addEvents(100, secondsToNs(0.07));
  ASSERT_TRUE(sync.poll(&set));
  EXPECT_EQ(set.t_ns, secondsToNs(0.07));
  EXPECT_TRUE(set.features[0].has_previous);
  EXPECT_LT((set.features[0].uv_previous - linear(a0, va, 0.05)).norm(), 1e-9);
  EXPECT_LT((set.features[0].uv - linear(a0, va, 0.07)).norm(), 1e-9);
  EXPECT_LT((set.features[1].uv - linear(b0, vb, 0.07)).norm(), 1e-9);
  EXPECT_LT((set.features[1].uv_previous - linear(b0, vb, 0.05)).norm(), 1e-9);
}

// The covariance a tracker states for a point goes with it into every set
// until a newer point replaces it; repeats of an old point and positions
// closer than min_displacement_px to the last informative one are flagged
// not informative.
TEST(Synchronizer, CarriesThePointCovarianceAndErrorTimeAndFlagsRepeatedOrStillPositions) {
  SynchronizerOptions o;
  o.n_e = 10;
  o.drop_repeated_points = true;
  o.min_displacement_px = 1.0;
  Synchronizer sync(o);
  TrackPoint a = point(1, 0.00, Vec2(10, 10), TrackStatus::kNew);
  TrackPoint b = point(2, 0.00, Vec2(50, 50), TrackStatus::kNew);
  a.cov_px << 0.04, 0.01, 0.01, 0.09;
  a.error_time_s = 0.054;
  sync.addTrackPoints({a, b});
  sync.addEvents(10, secondsToNs(0.0));
  MeasurementSet set;
  ASSERT_TRUE(sync.poll(&set));
  ASSERT_EQ(set.features.size(), 2u);
  EXPECT_EQ(set.features[0].cov_px, a.cov_px);
  EXPECT_EQ(set.features[1].cov_px, Mat2::Zero());  // not stated
  EXPECT_EQ(set.features[0].error_time_s, 0.054);
  EXPECT_EQ(set.features[1].error_time_s, 0.0);  // not stated: independent
  EXPECT_TRUE(set.features[0].informative);
  EXPECT_TRUE(set.features[1].informative);

  // Track 1 moves 0.5 px (below the threshold), track 2 has no new point.
  TrackPoint a2 = point(1, 0.01, Vec2(10.5, 10));
  a2.cov_px = 4.0 * Mat2::Identity();
  a2.error_time_s = 0.02;
  sync.addTrackPoints({a2});
  sync.addEvents(10, secondsToNs(0.01));
  ASSERT_TRUE(sync.poll(&set));
  EXPECT_EQ(set.features[0].cov_px, a2.cov_px);
  EXPECT_EQ(set.features[0].error_time_s, 0.02);  // the newest point's
  EXPECT_FALSE(set.features[0].informative);  // 0.5 px < 1 px
  EXPECT_FALSE(set.features[1].informative);  // a repeat of the point at 0 s

  // Track 1 reaches 1.2 px from its last informative position (10, 10).
  sync.addTrackPoints({point(1, 0.02, Vec2(11.2, 10)), point(2, 0.02, Vec2(50.2, 50))});
  sync.addEvents(10, secondsToNs(0.02));
  ASSERT_TRUE(sync.poll(&set));
  EXPECT_TRUE(set.features[0].informative);
  EXPECT_FALSE(set.features[1].informative);  // new point, but 0.2 px from (50, 50)

  // By default every position is informative, as before.
  Synchronizer plain{SynchronizerOptions{}};
  plain.addTrackPoints({point(1, 0.0, Vec2(1, 1), TrackStatus::kNew)});
  plain.addEvents(3200, secondsToNs(0.0));
  plain.addEvents(3200, secondsToNs(0.01));
  ASSERT_TRUE(plain.poll(&set));
  EXPECT_TRUE(set.features[0].informative);
}

// A tracker with an exactly known latency τ: its point stamped t shows the
// true position at t − τ. Compensating τ gives the true position at the set
// time exactly (linear motion); without it the set trails by v τ.
TEST(Synchronizer, CompensatesAKnownTrackerLatencyAlongTheTrackVelocity) {
  const double tau = 0.0015;
  const Vec2 uv0(40, 30), v(200, -120);  // px, px/s
  const auto lagged = [&](FeatureId id, double t, TrackStatus st = TrackStatus::kTracked) {
    return point(id, t, linear(uv0, v, t - tau), st);
  };
  SynchronizerOptions o;
  o.n_e = 10;
  o.track_latency_s = tau;
  Synchronizer sync(o);
  Synchronizer plain(SynchronizerOptions{.n_e = 10});
  for (Synchronizer* s : {&sync, &plain}) {
    s->addTrackPoints({lagged(1, 0.010, TrackStatus::kNew), lagged(1, 0.012), lagged(1, 0.014)});
    s->addEvents(10, secondsToNs(0.014));
  }
  MeasurementSet set, set_plain;
  ASSERT_TRUE(sync.poll(&set));
  ASSERT_TRUE(plain.poll(&set_plain));
  EXPECT_EQ(set.t_ns, secondsToNs(0.014));
  EXPECT_LT((set.features[0].uv - linear(uv0, v, 0.014)).norm(), 1e-9);
  EXPECT_NEAR((set_plain.features[0].uv - linear(uv0, v, 0.014)).norm(), v.norm() * tau, 1e-9);

  o.track_latency_s = 0.06;  // beyond the range [0, 0.05] s
  EXPECT_THROW(Synchronizer{o}, Error);
}

// A tracker whose lag is a + τ|v| (a px in distance, τ in time): the lag
// of EKLT measured against the simulator's truth. Compensating both gives
// the true position at the set time exactly, for a slow and a fast track;
// the distance alone leaves the slow one's τ|v| (small) and the fast one's
// (large) behind.
TEST(Synchronizer, CompensatesALagInDistanceAndTimeAtAnySpeed) {
  const double a = 0.4, tau = 0.0013;
  const Vec2 uv0(40, 30), slow(12, -9), fast(800, 600);  // px, px/s: |slow| 15, |fast| 1000
  const auto lagged = [&](FeatureId id, const Vec2& v, double t, TrackStatus st = TrackStatus::kTracked) {
    return point(id, t, linear(uv0, v, t - tau) - a * v.normalized(), st);
  };
  // The velocity from the newest two points or fitted over 20 ms (all three
  // points here) is the same on a line; the set comes at 15 ms, 1 ms after
  // the slow track's newest point (extrapolated) and at the fast one's.
  for (const double window : {0.0, 0.02}) {
    const SynchronizerOptions o = lagOptions(tau, a, window);
    SynchronizerOptions distance_only = o;
    distance_only.track_latency_s = 0.0;
    Synchronizer sync(o), partial(distance_only);
    for (Synchronizer* s : {&sync, &partial}) {
      s->addTrackPoints({lagged(1, slow, 0.010, TrackStatus::kNew), lagged(2, fast, 0.010, TrackStatus::kNew),
                         lagged(1, slow, 0.012), lagged(2, fast, 0.012), lagged(1, slow, 0.014),
                         lagged(2, fast, 0.015)});
      s->addEvents(10, secondsToNs(0.015));
    }
    MeasurementSet set, set_partial;
    ASSERT_TRUE(sync.poll(&set));
    ASSERT_TRUE(partial.poll(&set_partial));
    ASSERT_EQ(set.features.size(), 2u);
    ASSERT_EQ(set.t_ns, secondsToNs(0.015));
    for (const FeatureMeasurement& m : set.features) {
      const Vec2 truth = linear(uv0, m.id == 1 ? slow : fast, 0.015);
      EXPECT_LT((m.uv - truth).norm(), 1e-9) << "feature " << m.id << ", window " << window;
    }
    for (const FeatureMeasurement& m : set_partial.features) {
      const Vec2 v = m.id == 1 ? slow : fast;
      EXPECT_NEAR((m.uv - linear(uv0, v, 0.015)).norm(), v.norm() * tau, 1e-9) << "feature " << m.id;
    }
  }
  SynchronizerOptions o;
  o.track_lag_px = 11.0;  // beyond the range [0, 10] px
  EXPECT_THROW(Synchronizer{o}, Error);
  o = SynchronizerOptions{};
  o.velocity_window_s = -0.01;
  EXPECT_THROW(Synchronizer{o}, Error);
  o.velocity_window_s = 1.5;  // beyond the range [0, 1] s
  EXPECT_THROW(Synchronizer{o}, Error);
}

// EKLT measures a track's first two points on frames (its detection and its
// bootstrap on the next frame), at the frames' times: they do not lag. A set
// whose newest point for a track is such a point sends the exact linear
// extrapolation, with neither the lag distance a nor the latency τ added:
// track 7 at 48 ms, 2 ms past its bootstrap (the set's time comes from
// track 8's newest point); track 9 the same, its bootstrap replacing a
// lagged point of the same time. Once event points (lagged by a + τ|v|) are
// the newest, both are compensated again. Exact on a line, to 1e-9 px.
TEST(Synchronizer, CompensatesNoLagForPointsMeasuredOnFrames) {
  const double a = 0.4, tau = 0.0013;
  const Vec2 uv0(40, 30), v(300, -200);  // px, px/s
  const auto onFrame = [&](FeatureId id, double t, TrackStatus st) {
    TrackPoint p = point(id, t, linear(uv0, v, t), st);
    p.measured_on_frame = true;
    return p;
  };
  const auto lagged = [&](FeatureId id, double t) {
    return point(id, t, linear(uv0, v, t - tau) - a * v.normalized());
  };
  for (const double window : {0.0, 0.02}) {
    Synchronizer sync(lagOptions(tau, a, window));
    sync.addTrackPoints({onFrame(7, 0.000, TrackStatus::kNew), onFrame(9, 0.000, TrackStatus::kNew),
                         onFrame(7, 0.046, TrackStatus::kTracked), lagged(9, 0.046),
                         onFrame(9, 0.046, TrackStatus::kTracked), lagged(8, 0.030), lagged(8, 0.048)});
    sync.addEvents(10, secondsToNs(0.049));
    MeasurementSet set;
    ASSERT_TRUE(sync.poll(&set));
    ASSERT_EQ(set.t_ns, secondsToNs(0.048));
    ASSERT_EQ(set.features.size(), 3u);
    for (const FeatureMeasurement& m : set.features)
      EXPECT_LT((m.uv - linear(uv0, v, 0.048)).norm(), 1e-9) << "feature " << m.id << ", window " << window;
    // Event points of tracks 7 and 9, 24 and 26 ms after the bootstrap (so
    // that the velocity comes from lagged points alone, in either window).
    sync.addTrackPoints({lagged(7, 0.070), lagged(9, 0.070), lagged(7, 0.072), lagged(9, 0.072)});
    sync.addEvents(10, secondsToNs(0.073));
    ASSERT_TRUE(sync.poll(&set));
    ASSERT_EQ(set.t_ns, secondsToNs(0.072));
    for (const FeatureMeasurement& m : set.features) {
      if (m.id != 8) {
        EXPECT_LT((m.uv - linear(uv0, v, 0.072)).norm(), 1e-9) << "feature " << m.id;
      }
    }
  }
}

// A fitted velocity carries less of a noisy track's point noise into what
// is sent: nine points 2.5 ms apart, each off by σ = 0.5 px per axis (about
// EKLT's on the campaign cells), a latency τ = 2 ms compensated. The set
// comes at the newest point's time t_n, so the sent position is the newest
// point moved τ along the slope: its error is e_n + τ ê_v. For a
// least-squares slope over n points with S = Σ (t_k − t̄)²,
//   Var = σ² (1 + 2 τ (t_n − t̄) / S + τ² / S):
// the newest two points (t_n − t̄ = h/2, S = h²/2) give σ² (1 + 2τ/h + 2τ²/h²)
// = 0.970 px²; all nine (t_n − t̄ = 4h, S = 60 h²) σ² (1 + 8τ/(60h) + τ²/(60h²))
// = 0.2793 px². Measured over 4000 tracks (8000 axis samples, standard error
// of the variance 1.6 %), each within 5 %; the mean error within 4 standard
// errors of zero (the fit is unbiased on a line).
TEST(Synchronizer, AFittedVelocityCarriesLessNoiseIntoTheSentPosition) {
  const double sigma = 0.5, h = 0.0025, tau = 0.002;
  const Vec2 uv0(50, 60), v(300, -200);  // px, px/s
  const std::vector<std::pair<double, double>> cases = {
      {0.0, sigma * sigma * (1 + 2 * tau / h + 2 * tau * tau / (h * h))},
      {0.021, sigma * sigma * (1 + 8 * tau / (60 * h) + tau * tau / (60 * h * h))}};  // window, expected variance
  for (const auto& [window, expected] : cases) {
    SynchronizerOptions o;
    o.n_e = 1;
    o.track_latency_s = tau;
    o.velocity_window_s = window;
    std::mt19937_64 rng(7);
    std::normal_distribution<double> noise(0.0, sigma);
    double sum = 0.0, sum_sq = 0.0;
    const int trials = 4000;
    for (int trial = 0; trial < trials; ++trial) {
      Synchronizer sync(o);
      TrackPoints points;
      double t_n = 0.0;
      for (int k = 0; k < 9; ++k) {
        t_n = 0.01 + k * h;
        points.push_back(point(1, t_n, linear(uv0, v, t_n - tau) + Vec2(noise(rng), noise(rng)),
                               k == 0 ? TrackStatus::kNew : TrackStatus::kTracked));
      }
      sync.addTrackPoints(points);
      sync.addEvents(1, secondsToNs(t_n));
      MeasurementSet set;
      ASSERT_TRUE(sync.poll(&set));
      ASSERT_EQ(set.t_ns, secondsToNs(t_n));
      const Vec2 e = set.features[0].uv - linear(uv0, v, t_n);
      sum += e.x() + e.y();
      sum_sq += e.squaredNorm();
    }
    const double n = 2.0 * trials;
    EXPECT_NEAR(sum_sq / n, expected, 0.05 * expected) << "window " << window;
    EXPECT_LT(std::abs(sum / n), 4.0 * std::sqrt(expected / n)) << "window " << window;
  }
}

TEST(Synchronizer, UpdateTimeMustBeStrictlyAfterThePreviousAndLostTracksLeave) {
  SynchronizerOptions o;
  o.n_e = 10;
  Synchronizer sync(o);
  sync.addTrackPoints({point(1, 0.10, Vec2(1, 1), TrackStatus::kNew), point(2, 0.10, Vec2(5, 5), TrackStatus::kNew)});
  sync.addEvents(10, secondsToNs(0.1));
  MeasurementSet set;
  ASSERT_TRUE(sync.poll(&set));
  // A point at the same time replaces the newest point and marks the track
  // moved, but the latest time stays 0.10: no update.
  sync.addTrackPoints({point(2, 0.10, Vec2(5.5, 5))});
  sync.addEvents(10, secondsToNs(0.1));
  EXPECT_FALSE(sync.poll(&set));
  sync.addTrackPoints({point(2, 0.12, Vec2(6, 5)), point(1, 0.12, Vec2(1, 1), TrackStatus::kLost)});
  sync.addEvents(10, secondsToNs(0.12));
  ASSERT_TRUE(sync.poll(&set));
  ASSERT_EQ(set.features.size(), 1u);
  EXPECT_EQ(set.features[0].id, 2);
  EXPECT_EQ(sync.numLiveTracks(), 1u);
}

TEST(Synchronizer, FixedRateAndMinimumRate) {
  SynchronizerOptions o;
  o.trigger = "fixed_rate";
  o.rate_hz = 100.0;
  Synchronizer fixed(o);
  fixed.addTrackPoints({point(1, 0.0, Vec2(0, 0), TrackStatus::kNew), point(1, 0.01, Vec2(1, 0))});
  fixed.advanceTime(secondsToNs(0.0));
  fixed.advanceTime(secondsToNs(0.035));
  MeasurementSet set;
  std::vector<TimeNs> times;
  while (fixed.poll(&set)) {
    times.push_back(set.t_ns);
    // Extrapolated at 100 px/s, capped at max_extrapolation_s (0.1 s) past 0.01.
    EXPECT_NEAR(set.features[0].uv.x(), 100.0 * nsToSeconds(set.t_ns), 1e-9);
  }
  EXPECT_EQ(times, (std::vector<TimeNs>{secondsToNs(0.01), secondsToNs(0.02), secondsToNs(0.03)}));

  SynchronizerOptions m;
  m.n_e = 1000000;
  m.min_rate_hz = 10.0;
  Synchronizer minimum(m);
  minimum.addTrackPoints({point(7, 1.0, Vec2(3, 4), TrackStatus::kNew)});
  minimum.advanceTime(secondsToNs(1.0));
  minimum.advanceTime(secondsToNs(1.05));
  EXPECT_FALSE(minimum.poll(&set));
  minimum.advanceTime(secondsToNs(1.1));
  ASSERT_TRUE(minimum.poll(&set));  // no events at all, yet an update at 10 Hz
  EXPECT_EQ(set.t_ns, secondsToNs(1.1));
  EXPECT_EQ(set.features[0].uv, Vec2(3, 4));  // one point: held
}

TEST(Synchronizer, TrackTimeTriggerGivesOneUpdatePerFrame) {
  SynchronizerOptions o;
  o.trigger = "track_time";
  Synchronizer sync(o);
  MeasurementSet set;
  for (int f = 0; f < 3; ++f) {
    TrackPoints pts;
    for (FeatureId id = 0; id < 4; ++id)
      pts.push_back(point(id, 0.05 * f, Vec2(id, f), f == 0 ? TrackStatus::kNew : TrackStatus::kTracked));
    sync.addTrackPoints(pts);
    ASSERT_TRUE(sync.poll(&set));
    EXPECT_EQ(set.t_ns, secondsToNs(0.05 * f));
    EXPECT_EQ(set.features.size(), 4u);
    EXPECT_FALSE(sync.poll(&set));
  }
}

TEST(Synchronizer, RejectsBadOptions) {
  SynchronizerOptions o;
  o.trigger = "sometimes";
  EXPECT_THROW(Synchronizer{o}, Error);
  o = SynchronizerOptions{};
  o.n_e = 0;
  EXPECT_THROW(Synchronizer{o}, Error);
  o = SynchronizerOptions{};
  o.min_displacement_px = -0.1;
  EXPECT_THROW(Synchronizer{o}, Error);
}

}  // namespace
}  // namespace evio::estimator

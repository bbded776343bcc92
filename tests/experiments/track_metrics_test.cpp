#include "evio/experiments/track_metrics.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"

namespace evio::experiments {
namespace {

using io::TrackSample;

/// A straight ground-truth track sampled every 10 ms over [t0, t1].
void addLine(std::vector<TrackSample>& out, std::int64_t id, double t0, double t1, Vec2 uv0, Vec2 v) {
  for (double t = t0; t <= t1 + 1e-9; t += 0.01) out.push_back({id, secondsToNs(t), uv0 + v * (t - t0)});
}

TEST(TrackMetrics, ErrorAgeAndAliveAreExact) {
  std::vector<TrackSample> truth, est;
  addLine(truth, 100, 0.0, 1.0, Vec2(10, 10), Vec2(20, 0));
  addLine(truth, 200, 0.0, 1.0, Vec2(50, 50), Vec2(0, 10));
  // Track 1 starts 0.5 px below 100 and drifts down at 1 px/s, sampled at odd
  // times: its error (the start offset is not counted) is t − 0 px.
  for (double t = 0.0; t <= 0.6 + 1e-9; t += 0.015) est.push_back({1, secondsToNs(t), Vec2(10 + 20 * t, 10.5 + t)});
  // Track 2 starts on 200, its error grows 10 px/s: passes 5 px at 0.5 s.
  for (double t = 0.2; t <= 0.9 + 1e-9; t += 0.1)
    est.push_back({2, secondsToNs(t), Vec2(50 + 10 * (t - 0.2), 50 + 10 * t)});
  // Track 3 starts nowhere near any ground truth: not matched.
  est.push_back({3, secondsToNs(0.1), Vec2(200, 200)});
  est.push_back({3, secondsToNs(0.2), Vec2(201, 200)});

  TrackMetricsOptions o;
  o.age_bin_s = 0.1;
  o.alive_bin_s = 0.5;
  const TrackMetrics m = evaluateTracks(est, truth, o);
  EXPECT_EQ(m.estimated_tracks, 3u);
  EXPECT_EQ(m.matched_tracks, 2u);
  // Track 1: 41 samples with error t (sum 0.015 · (0 + 1 + … + 40) = 12.3);
  // track 2: errors 0, 1, 2, 3 px (ages 0…0.3); at age 0.4 (t = 0.6) 4 px,
  // at 0.5 5 px (≤ 5 still counts), at 0.6 6 px: its scored life ends at 0.5.
  EXPECT_EQ(m.scored_samples, 41u + 6u);
  EXPECT_NEAR(m.mean_error_px, (12.3 + 0 + 1 + 2 + 3 + 4 + 5) / 47.0, 1e-9);
  EXPECT_NEAR(m.mean_feature_age_s, 0.5 * (0.6 + 0.5), 1e-9);
  ASSERT_GE(m.error_vs_age.size(), 6u);
  EXPECT_NEAR(m.error_vs_age[0].age_s, 0.0, 1e-12);
  // Age bin [0, 0.1): track 1 ages 0…0.09 (7 samples, errors 0.015 k) plus
  // track 2 at age 0.
  EXPECT_EQ(m.error_vs_age[0].samples, 8u);
  EXPECT_NEAR(m.error_vs_age[0].mean_error_px, 0.015 * (0 + 1 + 2 + 3 + 4 + 5 + 6) / 8.0, 1e-9);
  // Alive at 0, 0.5, 1.0 s: estimated 1 (track 1), 2 (tracks 1, 2), 0; truth 2 each.
  ASSERT_EQ(m.alive.size(), 3u);
  EXPECT_EQ(m.alive[0].estimated, 1u);
  EXPECT_EQ(m.alive[1].estimated, 2u);
  EXPECT_EQ(m.alive[2].estimated, 0u);
  EXPECT_EQ(m.alive[1].truth, 2u);
  EXPECT_NE(trackMetricsJson(m).find("\"matched_tracks\": 2"), std::string::npos);
  EXPECT_EQ(errorVsAgeCsv(m).rfind("age_s,mean_error_px,samples\n0,", 0), 0u) << errorVsAgeCsv(m);
}

TEST(TrackMetrics, IdMatchingAndGroundTruthGaps) {
  std::vector<TrackSample> truth = {{5, secondsToNs(0.0), Vec2(0, 0)}, {5, secondsToNs(0.1), Vec2(1, 0)},
                                    {5, secondsToNs(0.5), Vec2(5, 0)}};  // a 0.4 s gap (occlusion)
  std::vector<TrackSample> est = {{5, secondsToNs(0.0), Vec2(3, 0)}, {5, secondsToNs(0.05), Vec2(3.5, 0)},
                                  {5, secondsToNs(0.3), Vec2(3, 0)}};
  TrackMetricsOptions o;
  o.match = "id";
  const TrackMetrics m = evaluateTracks(est, truth, o);
  EXPECT_EQ(m.matched_tracks, 1u);  // 3 px apart at the start, but the ids match
  EXPECT_EQ(m.scored_samples, 2u);  // scoring stops in the gap
  EXPECT_NEAR(m.mean_error_px, 3.0, 1e-12);
  o.match = "nearest";
  EXPECT_EQ(evaluateTracks(est, truth, o).matched_tracks, 0u);  // 3 px > 2 px radius
  o.match = "closest";
  EXPECT_THROW(evaluateTracks(est, truth, o), Error);
}

}  // namespace
}  // namespace evio::experiments

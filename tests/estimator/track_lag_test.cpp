// The online estimate of an event tracker's lag (track_lag.h): the fit
// against exact samples, and the probe on frames of a moving texture with
// event tracks whose lag a + τ|v| is known exactly.
#include "evio/estimator/frontend/track_lag.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"

namespace evio::estimator {
namespace {

TEST(TrackLagFit, RecoversDistanceAndTimeFromExactSamples) {
  TrackLagFit fit;
  for (int k = 0; k < 1000; ++k) {
    const double speed = 50.0 + 0.45 * k;  // 50 … 500 px/s
    fit.add(speed, 0.3 + 0.002 * speed);
  }
  const TrackLag lag = fit.solve();
  // The prior (one sample at 0, 0) against 1000 samples moves it by < 1 %.
  EXPECT_NEAR(lag.a_px, 0.3, 0.003);
  EXPECT_NEAR(lag.tau_s, 0.002, 2e-5);
  EXPECT_DOUBLE_EQ(fit.effectiveSamples(), 1000.0);
  fit.forget(0.5);
  EXPECT_DOUBLE_EQ(fit.effectiveSamples(), 500.0);
  EXPECT_NEAR(fit.solve().a_px, 0.3, 0.006);
}

TEST(TrackLagFit, AtOneSpeedGivesTheLagAtThatSpeed) {
  TrackLagFit fit;
  for (int k = 0; k < 500; ++k) fit.add(200.0, 0.8);
  const TrackLag lag = fit.solve();
  // a and τ are not separable; their sum at 200 px/s is the lag (prior: 1 sample).
  EXPECT_NEAR(lag.a_px + lag.tau_s * 200.0, 0.8, 0.01);
}

TEST(TrackLagFit, ALeadIsNotALag) {
  // Samples whose best free fit has τ < 0 (lag falling with speed): the fit
  // keeps τ = 0 and fits a alone, the mean lag (prior: one sample at 0).
  TrackLagFit fit;
  for (int k = 0; k < 400; ++k) {
    const double speed = 100.0 + k;
    fit.add(speed, 0.5 - 0.001 * speed);
  }
  const TrackLag lag = fit.solve();
  EXPECT_EQ(lag.tau_s, 0.0);
  EXPECT_NEAR(lag.a_px, (0.5 - 0.001 * 299.5) * 400.0 / 401.0, 1e-9);
}

TEST(TrackLagOptions, BadValuesNameTheField) {
  TrackLagOptions o;
  o.window_px = 20;
  EXPECT_THROW(o.validate(), Error);
  o = TrackLagOptions{};
  o.memory_s = 0.0;
  EXPECT_THROW(o.validate(), Error);
}

// A smooth random texture moving at velocity v(t) (40 px/s for 1 s, then
// 300 px/s, along a diagonal), 50 Hz frames rendered exactly by sub-pixel
// shifts, 12 features. Their event tracks (a point every 2 ms) trail the truth
// by a = 0.4 px along the motion and τ = 1.5 ms in time. The probe, fed
// the frames and the points as a tracker would emit them, recovers a and τ:
// measured |Δa| 0.007 px and |Δτ| 0.10 ms (721 effective samples); within
// 0.1 px and 0.3 ms.
class MovingTexture {
 public:
  MovingTexture() {
    RandomStream rng(7, "texture");
    cv::Mat noise(360, 420, CV_32F);
    for (int r = 0; r < noise.rows; ++r)
      for (int c = 0; c < noise.cols; ++c) noise.at<float>(r, c) = static_cast<float>(rng.uniform());
    cv::GaussianBlur(noise, texture_, cv::Size(0, 0), 2.0);
    cv::normalize(texture_, texture_, 20.0, 235.0, cv::NORM_MINMAX);
  }
  /// Displacement of the texture at t, px.
  static Vec2 offset(double t) {
    const Vec2 dir = Vec2(1.0, 0.6).normalized();
    const double d = t < 1.0 ? 40.0 * t : 40.0 + 300.0 * (t - 1.0);
    return d * dir;
  }
  static Vec2 velocity(double t) { return (t < 1.0 ? 40.0 : 300.0) * Vec2(1.0, 0.6).normalized(); }
  /// 240 × 180 frame of the texture shifted by offset(t) (bilinear, 8 bit).
  cv::Mat frame(double t) const {
    const Vec2 d = offset(t);
    cv::Mat M = (cv::Mat_<double>(2, 3) << 1, 0, d.x() - 60.0, 0, 1, d.y() - 60.0);
    cv::Mat shifted, out;
    cv::warpAffine(texture_, shifted, M, cv::Size(240, 180), cv::INTER_LINEAR);
    shifted.convertTo(out, CV_8U);
    return out;
  }

 private:
  cv::Mat texture_;
};

/// Twelve feature seeds on a 4 × 3 grid inside the 240 × 180 frame, px.
std::vector<Vec2> seedGrid() {
  std::vector<Vec2> seeds;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) seeds.emplace_back(40.0 + 30.0 * i, 40.0 + 25.0 * j);
  return seeds;
}

TEST(FrameLagProbe, RecoversAKnownLagFromFramesAndEventTracks) {
  const double a = 0.4, tau = 0.0015;
  const MovingTexture scene;
  const std::vector<Vec2> seeds = seedGrid();
  TrackLagOptions o;
  o.estimate = true;
  o.min_samples = 10;
  FrameLagProbe probe(o);
  const auto truth = [&](std::size_t i, double t) { return Vec2(seeds[i] + MovingTexture::offset(t)); };
  const double frame_dt = 0.02, point_dt = 0.002, end = 1.6;
  double next_point = 0.0;
  for (int k = 0; k * frame_dt <= end + 1e-9; ++k) {
    const double t_f = k * frame_dt;
    // The event points up to the frame (strictly before it), lagged.
    TrackPoints points;
    for (; next_point < t_f - 1e-9; next_point += point_dt) {
      if (next_point <= 1e-9) continue;
      for (std::size_t i = 0; i < seeds.size(); ++i) {
        const Vec2 v = MovingTexture::velocity(next_point);
        points.push_back(TrackPoint{static_cast<FeatureId>(i), secondsToNs(next_point),
                                    truth(i, next_point - tau) - a * v.normalized(), 1.0, TrackStatus::kTracked});
      }
    }
    probe.observe(points, 0);
    probe.addFrame(secondsToNs(t_f), scene.frame(t_f));
    if (k == 0) {  // the tracker seeds its features on the first frame
      TrackPoints seeds_points;
      for (std::size_t i = 0; i < seeds.size(); ++i)
        seeds_points.push_back(TrackPoint{static_cast<FeatureId>(i), 0, truth(i, 0.0), 1.0, TrackStatus::kNew});
      probe.observe(seeds_points, 0);
    }
  }
  const std::optional<TrackLag> lag = probe.lag();
  ASSERT_TRUE(lag.has_value());
  std::printf("estimated a = %.3f px, tau = %.3f ms from %.0f effective samples\n", lag->a_px, 1e3 * lag->tau_s,
              probe.effectiveSamples());
  EXPECT_NEAR(lag->a_px, a, 0.1);
  EXPECT_NEAR(lag->tau_s, tau, 3e-4);
}

// The probe's event track is made of event points alone. Twelve features
// are detected on the frame at 0 and bootstrapped on the frame at 20 ms
// (points measured on frames, on the truth), then give one lagged event
// point at 30 ms. At the frame at 40 ms no feature has two event points,
// so no sample is taken: a line through the bootstrap and the lagged point
// would not move at the feature's speed (with a = 0.4 px, τ = 1.5 ms at
// 40 px/s it would put the sample about 0.46 px too far behind).
TEST(FrameLagProbe, TakesNoSampleThroughAPointMeasuredOnAFrame) {
  const double a = 0.4, tau = 0.0015;
  const MovingTexture scene;
  const std::vector<Vec2> seeds = seedGrid();
  const auto truth = [&](std::size_t i, double t) { return Vec2(seeds[i] + MovingTexture::offset(t)); };
  const auto points = [&](double t, TrackStatus status, bool on_frame) {
    TrackPoints out;
    for (std::size_t i = 0; i < seeds.size(); ++i) {
      const Vec2 lag = on_frame ? Vec2::Zero() : Vec2(a * MovingTexture::velocity(t).normalized());
      TrackPoint p{static_cast<FeatureId>(i), secondsToNs(t), truth(i, on_frame ? t : t - tau) - lag, 1.0, status};
      p.measured_on_frame = on_frame;
      out.push_back(p);
    }
    return out;
  };
  TrackLagOptions o;
  o.estimate = true;
  FrameLagProbe probe(o);
  probe.addFrame(0, scene.frame(0.0));
  probe.observe(points(0.0, TrackStatus::kNew, true), 0);
  probe.addFrame(secondsToNs(0.02), scene.frame(0.02));
  probe.observe(points(0.02, TrackStatus::kTracked, true), 0);
  probe.observe(points(0.03, TrackStatus::kTracked, false), 0);
  probe.addFrame(secondsToNs(0.04), scene.frame(0.04));
  EXPECT_EQ(probe.effectiveSamples(), 0.0);
  // One more event point each, at 45 ms: the frame at 60 ms takes samples.
  probe.observe(points(0.045, TrackStatus::kTracked, false), 0);
  probe.addFrame(secondsToNs(0.06), scene.frame(0.06));
  EXPECT_GT(probe.effectiveSamples(), 0.0);
}

TEST(FrameLagProbe, NoLagWithoutSamples) {
  FrameLagProbe probe(TrackLagOptions{});
  EXPECT_FALSE(probe.lag().has_value());
}

}  // namespace
}  // namespace evio::estimator

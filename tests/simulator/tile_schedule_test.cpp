// The tile schedule (tile_schedule.h) against the sampler's rule: each
// tile's next sample is λ C over its fastest pixel's predicted log-rate,
// within the rate bounds, rounded down onto the time grid; only the tiles
// sampled are rescheduled; the result does not depend on the thread count.
#include "evio/simulator/tile_schedule.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "evio/core/error.h"

namespace evio::simulator {
namespace {

constexpr double kEps = 1e-3;

/// A 37 × 29 image (tiles of 8 px: 5 × 4, the last column and row narrower)
/// whose texture and flow vary from tile to tile, with a NaN pixel.
struct Images {
  cv::Mat radiance, flow;
  explicit Images(double phase = 0.0) : radiance(29, 37, CV_32FC1), flow(29, 37, CV_32FC2) {
    for (int y = 0; y < radiance.rows; ++y)
      for (int x = 0; x < radiance.cols; ++x) {
        radiance.at<float>(y, x) =
            static_cast<float>(std::exp(0.8 * std::sin(0.4 * x + phase) * std::cos(0.3 * y)) - 0.5 * kEps);
        flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(3.0 * x), static_cast<float>(-2.0 * y + 5.0));
      }
    radiance.at<float>(10, 12) = std::numeric_limits<float>::quiet_NaN();
  }
};

TEST(TileSchedule, EachTileIsDueAfterLambdaCOverItsFastestPixelOnTheGrid) {
  const Images im;
  for (const bool bound : {true, false}) {
    AdaptiveSampler::Options so;
    so.min_rate_hz = 50.0;
    so.max_rate_hz = 2000.0;
    so.rate_bound = bound;
    const AdaptiveSampler sampler(so, 0.2, kEps);
    const TimeNs origin = 1'000'000, quantum = 100'000, t = 1'730'000;  // t off the grid
    for (const int threads : {1, 2}) {
      TileSchedule s(37, 29, 8, so, 0.2, kEps, origin, quantum, threads);
      ASSERT_EQ(s.tileCount(), 20);
      EXPECT_EQ(s.tileRect(19), cv::Rect(32, 24, 5, 5));
      s.scheduleAll(t, im.radiance, im.flow);
      const cv::Mat l = sampler.logImage(im.radiance);
      for (int k = 0; k < s.tileCount(); ++k) {
        const cv::Rect r = s.tileRect(k);
        float rate = 0.0f;
        for (int y = r.y; y < r.y + r.height; ++y)
          for (int x = r.x; x < r.x + r.width; ++x) rate = std::max(rate, sampler.logRateAt(l, im.flow, x, y));
        const TimeNs dt = sampler.interval(rate);
        // Rounded down onto origin + j·quantum, and after t.
        const TimeNs expected = std::max(origin + (t + dt - origin) / quantum * quantum,
                                         origin + ((t - origin) / quantum + 1) * quantum);
        EXPECT_EQ(s.due(k), expected) << "tile " << k << ", rate_bound " << bound << ", threads " << threads;
        EXPECT_GT(s.due(k), t);
        EXPECT_LE(s.due(k), std::max(t + dt, origin + ((t - origin) / quantum + 1) * quantum));
      }
    }
  }
}

TEST(TileSchedule, OnlyTheTilesSampledAreRescheduled) {
  AdaptiveSampler::Options so;
  so.min_rate_hz = 50.0;
  so.max_rate_hz = 2000.0;
  TileSchedule s(37, 29, 8, so, 0.2, kEps, 0, 0);  // no grid: due = t + Δt
  const Images a(0.0), b(1.3);
  s.scheduleAll(0, a.radiance, a.flow);
  std::vector<TimeNs> before(20);
  for (int k = 0; k < 20; ++k) before[static_cast<std::size_t>(k)] = s.due(k);
  const TimeNs t = *std::min_element(before.begin(), before.end());
  EXPECT_EQ(s.nextTime(), t);
  std::vector<int> due;
  s.dueTiles(t, &due);
  ASSERT_FALSE(due.empty());
  for (const int k : due) EXPECT_EQ(s.due(k), t);
  s.scheduleTiles(t, due, b.radiance, b.flow);
  // Tiles not sampled keep their due time; sampled ones get t + Δt from the
  // latest sample of every pixel: b in the sampled tiles, a elsewhere.
  cv::Mat latest = a.radiance.clone();
  for (const int k : due) b.radiance(s.tileRect(k)).copyTo(latest(s.tileRect(k)));
  const AdaptiveSampler sampler(so, 0.2, kEps);
  const cv::Mat l = sampler.logImage(latest);
  for (int k = 0; k < 20; ++k) {
    TimeNs expected = before[static_cast<std::size_t>(k)];
    if (std::count(due.begin(), due.end(), k) > 0) {
      const cv::Rect r = s.tileRect(k);
      float rate = 0.0f;
      for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x) rate = std::max(rate, sampler.logRateAt(l, b.flow, x, y));
      expected = t + sampler.interval(rate);
    }
    EXPECT_EQ(s.due(k), expected) << k;
  }
  // Every tile sampled: the same as scheduling the whole new image.
  TileSchedule whole(37, 29, 8, so, 0.2, kEps, 0, 0);
  std::vector<int> all(20);
  for (int k = 0; k < 20; ++k) all[static_cast<std::size_t>(k)] = k;
  s.scheduleTiles(t + 1, all, b.radiance, b.flow);
  whole.scheduleAll(t + 1, b.radiance, b.flow);
  for (int k = 0; k < 20; ++k) EXPECT_EQ(s.due(k), whole.due(k)) << k;
  EXPECT_THROW(s.scheduleTiles(t + 2, {20}, b.radiance, b.flow), Error);
  EXPECT_THROW(s.scheduleAll(t + 2, cv::Mat(28, 37, CV_32FC1), b.flow), Error);
}

}  // namespace
}  // namespace evio::simulator

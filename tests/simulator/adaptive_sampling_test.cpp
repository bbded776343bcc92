// Adaptive sampling: the sampler's rule (λ C / |∇L·u̇v| within the rate
// bounds, per pixel or per tile), and the accuracy per-pixel adaptive
// sampling and the render loop's tile schedule keep against whole-frame
// sampling at a fine step, on an analytic
// texture rotating in the image with known flow (no renderer needed).
#include "evio/simulator/adaptive_sampler.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <iostream>
#include <random>
#include <vector>

#include "evio/core/error.h"
#include "evio/simulator/event_camera.h"
#include "evio/simulator/tile_schedule.h"

namespace evio::simulator {
namespace {

constexpr double kEps = 1e-3;

TEST(AdaptiveSampler, IntervalIsLambdaThresholdOverTheLogRateWithinBounds) {
  AdaptiveSampler::Options o;  // λ 0.5, 30 Hz .. 100 kHz
  o.rate_bound = false;        // |∇L · u̇v|
  const AdaptiveSampler s(o, 0.2, kEps);
  EXPECT_EQ(s.interval(10.0f), secondsToNs(0.5 * 0.2 / 10.0));  // 10 ms
  EXPECT_EQ(s.interval(0.0f), secondsToNs(1.0 / 30.0));          // minimum rate
  EXPECT_EQ(s.interval(1.0f), secondsToNs(1.0 / 30.0));          // 100 ms capped at 33 ms
  EXPECT_EQ(s.interval(1e7f), 10'000);                           // maximum rate
  EXPECT_EQ(s.interval(std::numeric_limits<float>::quiet_NaN()), secondsToNs(1.0 / 30.0));

  // L = a·x + b·y exactly (I = e^L − ε), flow (u, v): |dL/dt| = |a u + b v|.
  const int w = 16, h = 12;
  cv::Mat radiance(h, w, CV_32FC1), flow(h, w, CV_32FC2);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      radiance.at<float>(y, x) = static_cast<float>(std::exp(0.1 * x - 0.05 * y) - kEps);
      flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(10.0 + x), -20.0f);
    }
  const cv::Mat l = s.logImage(radiance);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      EXPECT_NEAR(static_cast<double>(s.logRateAt(l, flow, x, y)), std::abs(0.1 * (10.0 + x) + 0.05 * 20.0), 1e-4);
  std::vector<TimeNs> next;
  s.schedule(1000, radiance, flow, &next);
  ASSERT_EQ(next.size(), static_cast<std::size_t>(w * h));
  EXPECT_EQ(next[5], 1000 + s.interval(static_cast<float>(0.1 * 15.0 + 1.0)));
  // The whole-frame interval is the smallest per-pixel one.
  EXPECT_EQ(s.wholeFrameInterval(radiance, flow) + 1000, *std::min_element(next.begin(), next.end()));
  // Per 4 × 4 tile: every pixel of a tile gets the tile's smallest interval.
  AdaptiveSampler::Options tiled = o;
  tiled.tile_px = 4;
  std::vector<TimeNs> next_tiled;
  AdaptiveSampler(tiled, 0.2, kEps).schedule(1000, radiance, flow, &next_tiled);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      TimeNs tile_min = std::numeric_limits<TimeNs>::max();
      for (int yy = y / 4 * 4; yy < y / 4 * 4 + 4; ++yy)
        for (int xx = x / 4 * 4; xx < x / 4 * 4 + 4; ++xx) tile_min = std::min(tile_min, next[static_cast<std::size_t>(yy * w + xx)]);
      EXPECT_EQ(next_tiled[static_cast<std::size_t>(y * w + x)], tile_min);
    }
  // The bound: max neighbour slope / cos 22.5° · ‖u̇v‖; for this L the
  // steepest neighbour is the diagonal one, (0.1 + 0.05)/√2 = 0.10607 (x: 0.1).
  AdaptiveSampler::Options bound = o;
  bound.rate_bound = true;
  const AdaptiveSampler sb(bound, 0.2, kEps);
  for (int y = 1; y + 1 < h; ++y)
    for (int x = 1; x + 1 < w; ++x) {
      const double speed = std::hypot(10.0 + x, 20.0);
      EXPECT_NEAR(static_cast<double>(sb.logRateAt(l, flow, x, y)), 0.15 / std::sqrt(2.0) / std::cos(std::numbers::pi / 8.0) * speed,
                  1e-4 * speed);
      EXPECT_GE(sb.logRateAt(l, flow, x, y) * 1.0001f, s.logRateAt(l, flow, x, y));  // a bound
    }
  AdaptiveSampler::Options bad = o;
  bad.max_rate_hz = 10.0;
  EXPECT_THROW(AdaptiveSampler(bad, 0.2, kEps), Error);
}

/// A texture rotating about the image centre at ω rad/s: L(p, t) = T(R(−ωt)(p − c)),
/// flow u̇v(p) = ω (−(y − c_y), x − c_x).
struct RotatingTexture {
  int w = 64, h = 48;
  double omega = 2.0;
  double cx = 31.5, cy = 23.5;

  double logAt(double x, double y, double t) const {
    const double c = std::cos(omega * t), s = std::sin(omega * t);
    const double dx = x - cx, dy = y - cy;
    const double u = c * dx + s * dy, v = -s * dx + c * dy;  // R(−ωt)(p − c)
    return 1.0 + 0.9 * std::sin(0.35 * u + 0.5) * std::sin(0.27 * v) + 0.6 * std::sin(0.13 * u - 0.21 * v + 1.0);
  }
  float radianceAt(int x, int y, double t) const { return static_cast<float>(std::exp(logAt(x, y, t)) - kEps); }
  cv::Mat flow() const {
    cv::Mat f(h, w, CV_32FC2);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        f.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(-omega * (y - cy)), static_cast<float>(omega * (x - cx)));
    return f;
  }
};

/// Signal events per pixel, in order.
std::vector<std::vector<Event>> perPixel(const EventArray& ev, int w, int h) {
  std::vector<std::vector<Event>> out(static_cast<std::size_t>(w * h));
  for (std::size_t i = 0; i < ev.size(); ++i) out[static_cast<std::size_t>(ev[i].y * w + ev[i].x)].push_back(ev[i]);
  return out;
}

/// What one adaptive run kept against the reference.
struct Accuracy {
  double count_err = 0.0;       ///< Σ|n_adaptive − n_ref| / Σ n_ref over pixels
  double median_us = 0.0, p90_us = 0.0;  ///< |Δt| of the k-th events where counts agree
  double matched = 0.0;         ///< fraction of reference events so matched
  std::uint64_t updates = 0;    ///< pixel updates
  double on_err = 0.0, off_err = 0.0;  ///< |n_adaptive − n_ref| / n_ref of ON and of OFF events
};

/// ON events of a stream.
std::size_t onCount(const EventArray& ev) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < ev.size(); ++i) n += ev[i].positive ? 1 : 0;
  return n;
}

Accuracy compare(const EventArray& ev_ref, const EventArray& ev_ada, int w, int h) {
  const auto pr = perPixel(ev_ref, w, h), pa = perPixel(ev_ada, w, h);
  std::size_t count_ref = 0, count_diff = 0;
  std::vector<double> dt_us;
  for (std::size_t i = 0; i < pr.size(); ++i) {
    count_ref += pr[i].size();
    count_diff += pr[i].size() > pa[i].size() ? pr[i].size() - pa[i].size() : pa[i].size() - pr[i].size();
    if (pr[i].size() != pa[i].size()) continue;
    for (std::size_t k = 0; k < pr[i].size(); ++k) {
      EXPECT_EQ(pr[i][k].positive, pa[i][k].positive);
      dt_us.push_back(std::abs(static_cast<double>(pr[i][k].t_ns - pa[i][k].t_ns)) * 1e-3);
    }
  }
  std::sort(dt_us.begin(), dt_us.end());
  Accuracy a;
  a.count_err = static_cast<double>(count_diff) / static_cast<double>(count_ref);
  a.median_us = dt_us[dt_us.size() / 2];
  a.p90_us = dt_us[dt_us.size() * 9 / 10];
  a.matched = static_cast<double>(dt_us.size()) / static_cast<double>(count_ref);
  const auto rel = [](std::size_t n, std::size_t ref) {
    return std::abs(static_cast<double>(n) - static_cast<double>(ref)) / static_cast<double>(ref);
  };
  const std::size_t on_ref = onCount(ev_ref), on_ada = onCount(ev_ada);
  a.on_err = rel(on_ada, on_ref);
  a.off_err = rel(ev_ada.size() - on_ada, ev_ref.size() - on_ref);
  return a;
}

/// Per-pixel adaptive sampling of the texture: a pixel is sampled at the
/// first step at or after its due time; its next due time comes from the
/// latest L image and the flow.
Accuracy runAdaptive(const RotatingTexture& tex, const EventCamera::Options& eo, double lambda, TimeNs step,
                     int steps, const EventArray& ev_ref) {
  const int w = tex.w, h = tex.h;
  const std::size_t n = static_cast<std::size_t>(w * h);
  const cv::Mat flow = tex.flow();
  AdaptiveSampler::Options so;
  so.lambda = lambda;
  const AdaptiveSampler sampler(so, eo.threshold_pos, kEps);
  EventCamera ada(w, h, eo, 1);
  EventArray ev_ada;
  std::vector<float> img(n);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img[static_cast<std::size_t>(y * w + x)] = tex.radianceAt(x, y, 0.0);
  ada.update(0, img.data(), &ev_ada, nullptr);
  const cv::Mat radiance(h, w, CV_32FC1, img.data());
  cv::Mat l = sampler.logImage(radiance);
  std::vector<TimeNs> due;
  sampler.schedule(0, radiance, flow, &due);
  std::vector<int> sampled;
  for (int k = 1; k <= steps; ++k) {
    const TimeNs t = k * step;
    sampled.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (due[i] > t && k < steps) continue;
      const int x = static_cast<int>(i) % w, y = static_cast<int>(i) / w;
      const float v = tex.radianceAt(x, y, nsToSeconds(t));
      ada.updatePixel(i, t, v);
      l.at<float>(y, x) = std::log(static_cast<float>(kEps) + v);
      sampled.push_back(static_cast<int>(i));
    }
    for (const int i : sampled) due[static_cast<std::size_t>(i)] = sampler.schedulePixel(t, l, flow, i % w, i / w);
    ada.emit(&ev_ada, nullptr);
  }
  EXPECT_EQ(ada.pendingCount(), 0u);
  for (std::size_t i = 1; i < ev_ada.size(); ++i) EXPECT_LE(ev_ada.t()[i - 1], ev_ada.t()[i]);
  Accuracy a = compare(ev_ref, ev_ada, w, h);
  a.updates = ada.pixelUpdates();
  return a;
}

/// The render loop's tile schedule (tile_schedule.h) on the texture: at each
/// 20 µs step the tiles due are sampled (EventCamera::updateRects) and
/// rescheduled, then emit(); every tile is sampled at the last step.
Accuracy runTiles(const RotatingTexture& tex, const EventCamera::Options& eo, int tile_px, TimeNs step, int steps,
                  const EventArray& ev_ref) {
  const int w = tex.w, h = tex.h;
  const cv::Mat flow = tex.flow();
  AdaptiveSampler::Options so;  // λ 0.5, the default rate bounds
  TileSchedule schedule(w, h, tile_px, so, eo.threshold_pos, kEps, 0, step);
  EventCamera cam(w, h, eo, 1);
  EventArray ev;
  cv::Mat img(h, w, CV_32FC1);
  const auto render = [&](TimeNs t) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) img.at<float>(y, x) = tex.radianceAt(x, y, nsToSeconds(t));
  };
  render(0);
  cam.update(0, img, &ev, nullptr);
  schedule.scheduleAll(0, img, flow);
  std::vector<int> due;
  std::vector<cv::Rect> rects;
  for (int k = 1; k <= steps; ++k) {
    const TimeNs t = k * step;
    if (k == steps) {
      due.resize(static_cast<std::size_t>(schedule.tileCount()));
      for (int q = 0; q < schedule.tileCount(); ++q) due[static_cast<std::size_t>(q)] = q;
    } else {
      schedule.dueTiles(t, &due);
      EXPECT_GE(schedule.nextTime(), t);  // on the step grid no tile is ever overdue
      if (due.empty()) continue;
    }
    render(t);
    rects.clear();
    for (const int q : due) rects.push_back(schedule.tileRect(q));
    cam.updateRects(t, rects, img);
    schedule.scheduleTiles(t, due, img, flow);
    cam.emit(&ev, nullptr);
  }
  EXPECT_EQ(cam.pendingCount(), 0u);
  for (std::size_t i = 1; i < ev.size(); ++i) EXPECT_LE(ev.t()[i - 1], ev.t()[i]);
  Accuracy a = compare(ev_ref, ev, w, h);
  a.updates = cam.pixelUpdates();
  return a;
}

TEST(AdaptiveSampling, PerPixelSamplingKeepsTheAccuracyOfAFineWholeFrameStep) {
  RotatingTexture tex;
  tex.omega = 6.0;  // up to ≈ 240 px/s at the image edge
  const int w = tex.w, h = tex.h;
  const std::size_t n = static_cast<std::size_t>(w * h);
  const double duration = 0.2;
  const TimeNs step = 20'000;  // 20 µs: the fine whole-frame reference, also the adaptive time quantum
  const auto steps = static_cast<int>(std::llround(duration * 1e9 / static_cast<double>(step)));
  EventCamera::Options eo;
  eo.threshold_mismatch_sigma = 0.0;

  // Reference: every pixel at every step.
  EventCamera ref(w, h, eo, 1);
  EventArray ev_ref;
  std::vector<float> img(n);
  for (int k = 0; k <= steps; ++k) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) img[static_cast<std::size_t>(y * w + x)] = tex.radianceAt(x, y, nsToSeconds(k * step));
    ref.update(k * step, img.data(), &ev_ref, nullptr);
  }
  const double ref_updates = static_cast<double>(ref.pixelUpdates());

  // ESIM's whole-frame adaptive rule, for the update count.
  const cv::Mat flow = tex.flow();
  const AdaptiveSampler sampler(AdaptiveSampler::Options{}, eo.threshold_pos, kEps);
  std::uint64_t esim_updates = 0;
  for (TimeNs t = 0; t <= steps * step;) {
    cv::Mat r(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) r.at<float>(y, x) = tex.radianceAt(x, y, nsToSeconds(t));
    esim_updates += n;
    t += std::max(step, sampler.wholeFrameInterval(r, flow) / step * step);
  }

  std::cout << "adaptive sampling vs whole frames every 20 us (" << w << "x" << h << ", " << duration
            << " s, texture rotating at " << tex.omega << " rad/s): reference " << ev_ref.size() << " events, "
            << ref_updates << " pixel updates; ESIM whole-frame rule (lambda 0.5) " << esim_updates << " updates\n";
  Accuracy previous;
  for (const double lambda : {0.5, 0.1}) {
    const Accuracy a = runAdaptive(tex, eo, lambda, step, steps, ev_ref);
    std::cout << "  per-pixel lambda " << lambda << ": " << a.updates << " pixel updates ("
              << ref_updates / static_cast<double>(a.updates) << "x fewer), count error " << 100.0 * a.count_err
              << " %, matched " << 100.0 * a.matched << " %, time error median " << a.median_us << " us, p90 "
              << a.p90_us << " us\n";
    EXPECT_LT(a.count_err, 0.01) << lambda;
    EXPECT_GT(a.matched, 0.95) << lambda;
    EXPECT_LT(static_cast<double>(a.updates), 0.1 * ref_updates) << lambda;
    if (lambda == 0.5) {
      EXPECT_LT(a.median_us, 30.0);   // measured 9 µs
      EXPECT_LT(a.p90_us, 200.0);     // measured 60 µs
      EXPECT_LT(a.updates, esim_updates);
    } else {  // a smaller λ converges toward the reference
      EXPECT_LT(a.median_us, previous.median_us);
      EXPECT_LT(a.p90_us, previous.p90_us);
      EXPECT_LT(a.count_err, previous.count_err + 1e-3);
    }
    previous = a;
  }
  // Per tile (the render loop's "tiles" schedule): a tile's rate is that of
  // its fastest pixel, so it is sampled at least as often as each of its
  // pixels would be alone; the accuracy is at least the per-pixel one.
  for (const int tile_px : {4, 8, 16}) {
    const Accuracy a = runTiles(tex, eo, tile_px, step, steps, ev_ref);
    std::cout << "  tiles of " << tile_px << " px, lambda 0.5: " << a.updates << " pixel updates ("
              << ref_updates / static_cast<double>(a.updates) << "x fewer), count error " << 100.0 * a.count_err
              << " % (ON " << 100.0 * a.on_err << " %, OFF " << 100.0 * a.off_err << " %), matched "
              << 100.0 * a.matched << " %, time error median " << a.median_us << " us, p90 " << a.p90_us << " us\n";
    EXPECT_LT(a.count_err, 0.01) << tile_px;
    EXPECT_LT(a.on_err, 0.01) << tile_px;
    EXPECT_LT(a.off_err, 0.01) << tile_px;
    EXPECT_GT(a.matched, 0.95) << tile_px;
    EXPECT_LT(a.median_us, 30.0) << tile_px;
    EXPECT_LT(a.p90_us, 200.0) << tile_px;
    EXPECT_LT(static_cast<double>(a.updates), 0.1 * ref_updates) << tile_px;
    EXPECT_LT(a.updates, esim_updates) << tile_px;
  }
  EXPECT_GT(ev_ref.size(), 20000u);
}

TEST(AdaptiveSampler, KthSmallestIsTheValueNthElementSelects) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> spread(0.0f, 50.0f);
  std::uniform_int_distribution<int> level(0, 5);
  for (const std::size_t n : {std::size_t{1}, std::size_t{2}, std::size_t{17}, std::size_t{1000}, std::size_t{90000}}) {
    // Rates as the predictor's: many exact zeros, repeated values, a long tail;
    // a few negative values and −0 to check the ordering of the keys.
    std::vector<float> values(n);
    for (std::size_t i = 0; i < n; ++i) {
      const int l = level(rng);
      values[i] = l == 0 ? 0.0f : l == 1 ? 3.5f : l == 2 ? -0.0f : spread(rng) * spread(rng);
      if (i % 101 == 50) values[i] = -spread(rng);
    }
    const std::size_t step = n < 2000 ? 1 : 997;
    for (std::size_t k = 0; k < n; k += step) {
      std::vector<float> expected = values, scratch = values;
      std::nth_element(expected.begin(), expected.begin() + static_cast<std::ptrdiff_t>(k), expected.end());
      ASSERT_EQ(AdaptiveSampler::kthSmallest(&scratch, k), expected[k]) << "n " << n << " k " << k;
    }
    std::vector<float> scratch = values;
    EXPECT_EQ(AdaptiveSampler::kthSmallest(&scratch, n - 1), *std::max_element(values.begin(), values.end()));
  }
  std::vector<float> none;
  EXPECT_THROW(AdaptiveSampler::kthSmallest(&none, 0), Error);
}

TEST(AdaptiveSampler, LogRatesOfRowGivesTheBitsOfLogRateAt) {
  // A log image and a flow with the awkward values: equal neighbours, NaN
  // and infinite samples, zero, NaN, infinite and huge flow.
  const int w = 37, h = 9;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.0f, 3.0f);
  std::uniform_int_distribution<int> pick(0, 19);
  cv::Mat log_image(h, w, CV_32FC1), flow(h, w, CV_32FC2);
  const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int a = pick(rng), b = pick(rng);
      log_image.at<float>(y, x) = a == 0 ? nan : a == 1 ? -inf : a < 5 ? 1.5f : u(rng);
      flow.at<cv::Vec2f>(y, x) = b == 0   ? cv::Vec2f(nan, 1.0f)
                                 : b == 1 ? cv::Vec2f(inf, 0.0f)
                                 : b == 2 ? cv::Vec2f(0.0f, 0.0f)
                                 : b == 3 ? cv::Vec2f(3e19f, -3e19f)
                                          : cv::Vec2f(100.0f * u(rng), 100.0f * u(rng));
    }
  for (const bool bound : {true, false}) {
    AdaptiveSampler::Options o;
    o.rate_bound = bound;
    const AdaptiveSampler sampler(o, 0.3, 1e-3);
    for (int y = 0; y < h; ++y)
      for (const auto& [x0, x1] : {std::pair{0, w}, std::pair{1, 30}, std::pair{5, 6}, std::pair{20, w}}) {
        std::vector<float> rates(static_cast<std::size_t>(x1 - x0));
        sampler.logRatesOfRow(log_image, flow, y, x0, x1, rates.data());
        for (int x = x0; x < x1; ++x) {
          const float expected = sampler.logRateAt(log_image, flow, x, y), got = rates[static_cast<std::size_t>(x - x0)];
          ASSERT_EQ(std::memcmp(&got, &expected, sizeof(float)), 0)
              << "x " << x << " y " << y << ": " << got << " vs " << expected << " (rate_bound " << bound << ")";
        }
      }
  }
}

}  // namespace
}  // namespace evio::simulator

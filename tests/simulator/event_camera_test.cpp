// The event camera against exact ground truth: linear ramps of L give exactly
// the predicted events at the predicted times; Σ polarity·threshold
// reconstructs ΔL within one threshold; a static scene emits no signal; the
// refractory period holds while the reference follows; the output is
// time-sorted, and identical for any thread count and any pixel order.
#include "evio/simulator/event_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"
#include "evio/simulator/fast_math.h"

namespace evio::simulator {
namespace {

constexpr double kEps = 1e-3;  // default log_eps_w_m2_sr

/// Radiance whose L = log(ε + I) equals `l` (exactly, up to float rounding).
float radianceOfLog(double l) { return static_cast<float>(std::exp(l) - kEps); }

EventCamera::Options ideal() {
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.0;
  return o;
}

TEST(FastMath, LogAndExpAreAccurate) {
  double max_log_err = 0.0, max_exp_err = 0.0;
  for (int k = 0; k <= 200000; ++k) {
    const double x = std::pow(10.0, -4.0 + 9.0 * k / 200000.0);  // 1e-4 .. 1e5
    const auto xf = static_cast<float>(x);
    const double ref = std::log(static_cast<double>(xf));
    max_log_err = std::max(max_log_err, std::abs(static_cast<double>(fastLog(xf)) - ref) / std::max(1.0, std::abs(ref)));
    const auto y = static_cast<float>(-87.0 * k / 200000.0);
    const double e = std::exp(static_cast<double>(y));
    max_exp_err = std::max(max_exp_err, std::abs(static_cast<double>(fastExpNonPositive(y)) - e) / e);
  }
  EXPECT_LT(max_log_err, 2e-7);
  EXPECT_LT(max_exp_err, 3e-7);
  EXPECT_EQ(fastExpNonPositive(0.0f), 1.0f);
}

TEST(EventCamera, LinearRampEmitsThePredictedEventsAtThePredictedTimes) {
  // Pixel p has L(t) = L0 + s_p t over 100 ms, sampled every 1 ms; with
  // threshold C the k-th event is at t_k = k C / |s_p| (k = 1 .. floor(|ΔL| / C)).
  EventCamera::Options o = ideal();
  o.threshold_pos = 0.2;
  o.threshold_neg = 0.3;
  const std::vector<double> slopes = {3.33, -4.1, 17.0, -25.7, 333.0, -401.0, 0.0, 1.99};
  const int w = static_cast<int>(slopes.size());
  EventCamera cam(w, 1, o, 1);
  const double l0 = 35.0;  // L stays in (log ε, 88): from −5.1 to 68.3
  const TimeNs dt = kNsPerMs;
  std::vector<float> img(static_cast<std::size_t>(w));
  EventArray ev;
  std::vector<EventLabel> labels;
  for (int k = 0; k <= 100; ++k) {
    const double t = static_cast<double>(k) * 1e-3;
    for (int p = 0; p < w; ++p) img[static_cast<std::size_t>(p)] = radianceOfLog(l0 + slopes[static_cast<std::size_t>(p)] * t);
    cam.update(k * dt, img.data(), &ev, &labels);
  }
  ASSERT_EQ(ev.size(), labels.size());
  for (int p = 0; p < w; ++p) {
    const double s = slopes[static_cast<std::size_t>(p)];
    const double c = s > 0 ? o.threshold_pos : o.threshold_neg;
    const int expected = static_cast<int>(std::floor(std::abs(s) * 0.1 / c + 1e-9));
    std::vector<TimeNs> times;
    for (std::size_t i = 0; i < ev.size(); ++i) {
      if (ev[i].x != p) continue;
      EXPECT_EQ(ev[i].positive, s > 0);
      EXPECT_EQ(labels[i], EventLabel::kSignal);
      times.push_back(ev[i].t_ns);
    }
    ASSERT_EQ(static_cast<int>(times.size()), expected) << "slope " << s;
    for (int k = 1; k <= expected; ++k) {
      const double t_pred = k * c / std::abs(s) * 1e9;
      // float L (≈ 1e-7 relative) over a step of |s|·1 ms: well below 1 µs.
      EXPECT_NEAR(static_cast<double>(times[static_cast<std::size_t>(k - 1)]), t_pred, 1000.0)
          << "slope " << s << " event " << k;
    }
  }
}

TEST(EventCamera, StaticSceneEmitsNoSignalEvents) {
  EventCamera::Options o;  // mismatch on
  o.cutoff_max_hz = 300.0;
  o.shot_noise_rate_hz = 2.0;
  o.leak_rate_hz = 0.5;
  RandomStream rng(3, "test");
  const int w = 40, h = 30;
  std::vector<float> img(static_cast<std::size_t>(w * h));
  for (auto& v : img) v = static_cast<float>(std::exp(rng.uniform(-8.0, 5.0)));
  EventCamera cam(w, h, o, 5);
  EventArray ev;
  std::vector<EventLabel> labels;
  for (int k = 0; k <= 2000; ++k) cam.update(k * kNsPerMs, img.data(), &ev, &labels);
  EXPECT_GT(ev.size(), 100u);  // the noise is there…
  for (const auto l : labels) EXPECT_NE(l, EventLabel::kSignal);  // …but no signal
}

TEST(EventCamera, PolaritiesTimesThresholdsReconstructTheLogChange) {
  // Random walks of L per pixel; after every sample, with the pixel's own
  // thresholds C±_i: Σ_ON C⁺_i − Σ_OFF C⁻_i = r − r_0 and |ΔL − that| < C±_i.
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.05;
  const int w = 32, h = 24;
  const std::size_t n = static_cast<std::size_t>(w * h);
  EventCamera cam(w, h, o, 11);
  RandomStream rng(4, "test");
  std::vector<double> l(n);
  for (auto& v : l) v = rng.uniform(-3.0, 3.0);
  std::vector<double> l_start = l;
  std::vector<float> img(n);
  const auto fill = [&] {
    for (std::size_t i = 0; i < n; ++i) img[i] = radianceOfLog(l[i]);
  };
  fill();
  EventArray ev;
  std::vector<EventLabel> labels;
  cam.update(0, img.data(), &ev, &labels);
  std::vector<double> sum(n, 0.0);
  std::size_t seen = 0;
  for (int k = 1; k <= 300; ++k) {
    for (auto& v : l) v = std::clamp(v + rng.normal(0.0, 0.15), -5.0, 10.0);  // L > log ε
    fill();
    cam.update(k * kNsPerMs, img.data(), &ev, &labels);
    for (; seen < ev.size(); ++seen) {
      const Event e = ev[seen];
      const std::size_t i = static_cast<std::size_t>(e.y) * static_cast<std::size_t>(w) + e.x;
      sum[i] += e.positive ? static_cast<double>(cam.thresholdPos(i)) : -static_cast<double>(cam.thresholdNeg(i));
    }
    for (std::size_t i = 0; i < n; ++i) {
      const double dl = l[i] - l_start[i];
      const double r_change = static_cast<double>(cam.reference(i)) - l_start[i];
      ASSERT_NEAR(sum[i], r_change, 1e-4) << i;
      ASSERT_LT(dl - sum[i], static_cast<double>(cam.thresholdPos(i)) + 1e-5) << i;
      ASSERT_LT(sum[i] - dl, static_cast<double>(cam.thresholdNeg(i)) + 1e-5) << i;
    }
  }
  EXPECT_GT(ev.size(), 10000u);
}

TEST(EventCamera, RefractoryPeriodDropsEventsWhileTheReferenceFollows) {
  // L rises at 1000 /s with C = 0.2: a crossing every 0.2 ms; with a 1 ms
  // refractory period one event per ms is left, and r still tracks L.
  EventCamera::Options o = ideal();
  o.refractory_period_s = 1e-3;
  EventCamera cam(3, 1, o, 2);
  EventArray ev;
  std::vector<EventLabel> labels;
  for (int k = 0; k <= 500; ++k) {  // 50 ms at 0.1 ms
    const double t = k * 1e-4;
    const std::vector<float> img = {radianceOfLog(1000.0 * t), radianceOfLog(-1000.0 * t + 45.0),
                                    radianceOfLog(1.0)};
    cam.update(k * 100'000, img.data(), &ev, &labels);
  }
  for (int p = 0; p < 2; ++p) {
    std::vector<TimeNs> times;
    for (std::size_t i = 0; i < ev.size(); ++i)
      if (ev[i].x == p) times.push_back(ev[i].t_ns);
    ASSERT_GE(times.size(), 40u);
    ASSERT_LE(times.size(), 51u);
    for (std::size_t k = 1; k < times.size(); ++k) EXPECT_GE(times[k] - times[k - 1], kNsPerMs);
  }
  const double l_end[2] = {50.0, -5.0};
  EXPECT_LT(std::abs(static_cast<double>(cam.reference(0)) - l_end[0]), 0.2 + 1e-4);
  EXPECT_LT(std::abs(static_cast<double>(cam.reference(1)) - l_end[1]), 0.2 + 1e-4);
}

/// Records a run: events and labels of a sequence of random images.
struct EventRun {
  EventArray events;
  std::vector<EventLabel> labels;
};

EventCamera::Options noisy() {
  EventCamera::Options o;
  o.threshold_jitter_sigma = 0.02;
  o.refractory_period_s = 2e-4;
  o.cutoff_max_hz = 200.0;
  o.leak_rate_hz = 1.0;
  o.shot_noise_rate_hz = 5.0;
  o.hot_pixel_fraction = 0.01;
  o.hot_pixel_rate_hz = 50.0;
  return o;
}

std::vector<float> frameAt(int w, int h, int k) {
  // A moving pattern with dark and bright parts.
  std::vector<float> img(static_cast<std::size_t>(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      img[static_cast<std::size_t>(y * w + x)] =
          static_cast<float>(std::exp(3.0 * std::sin(0.3 * x + 0.02 * k) * std::cos(0.2 * y - 0.01 * k) - 1.0));
  return img;
}

TEST(EventCamera, OutputIsSortedAndIndependentOfThreadsAndPixelOrder) {
  const int w = 200, h = 180;  // > one parallel block
  const auto runWhole = [&](int threads) {
    EventCamera::Options o = noisy();
    o.threads = threads;
    EventCamera cam(w, h, o, 99);
    EventRun run;
    for (int k = 0; k <= 60; ++k) cam.update(k * 500'000, frameAt(w, h, k).data(), &run.events, &run.labels);
    return run;
  };
  const EventRun a = runWhole(1), b = runWhole(2);
  ASSERT_GT(a.events.size(), 1000u);
  EXPECT_TRUE(a.events == b.events);
  EXPECT_TRUE(a.labels == b.labels);
  for (std::size_t i = 1; i < a.events.size(); ++i) ASSERT_LE(a.events.t()[i - 1], a.events.t()[i]);
  for (const auto l : {EventLabel::kSignal, EventLabel::kLeak, EventLabel::kShot, EventLabel::kHot})
    EXPECT_NE(std::find(a.labels.begin(), a.labels.end(), l), a.labels.end()) << eventLabelName(l);

  // Per pixel, in reverse pixel order, at the same times: the same stream.
  EventCamera cam(w, h, noisy(), 99);
  EventRun c;
  cam.update(0, frameAt(w, h, 0).data(), &c.events, &c.labels);
  for (int k = 1; k <= 60; ++k) {
    const auto img = frameAt(w, h, k);
    if (k % 2 == 0) {
      for (std::size_t i = img.size(); i-- > 0;) cam.updatePixel(i, k * 500'000, img[i]);
    } else {  // the batch call, pixels in a shuffled order
      std::vector<std::uint32_t> idx(img.size());
      std::vector<float> val(img.size());
      for (std::size_t q = 0; q < img.size(); ++q) {
        idx[q] = static_cast<std::uint32_t>((q * 7919) % img.size());
        val[q] = img[idx[q]];
      }
      cam.updatePixels(k * 500'000, idx.data(), val.data(), idx.size());
    }
    EXPECT_EQ(cam.emit(&c.events, &c.labels), k * 500'000);
  }
  EXPECT_TRUE(a.events == c.events);
  EXPECT_TRUE(a.labels == c.labels);
}

TEST(EventCamera, UpdateRectsIsUpdatePixelsForEveryPixelOfTheRectangles) {
  const int w = 200, h = 180;  // > one parallel block of runs
  // Tiles of 16 px (the last column and row narrower), a changing subset of
  // them per step, every tile at least every third step.
  std::vector<cv::Rect> tiles;
  for (int y = 0; y < h; y += 16)
    for (int x = 0; x < w; x += 16) tiles.emplace_back(x, y, std::min(16, w - x), std::min(16, h - y));
  const auto subset = [&](int k) {
    std::vector<cv::Rect> out;
    for (std::size_t q = 0; q < tiles.size(); ++q)
      if ((q + static_cast<std::size_t>(k)) % 3 != 0 || k % 5 == 0) out.push_back(tiles[q]);
    return out;
  };
  const auto runRects = [&](int threads) {
    EventCamera::Options o = noisy();
    o.threads = threads;
    EventCamera cam(w, h, o, 99);
    EventRun run;
    cam.update(0, frameAt(w, h, 0).data(), &run.events, &run.labels);
    for (int k = 1; k <= 60; ++k) {
      const auto img = frameAt(w, h, k);
      cam.updateRects(k * 500'000, subset(k), cv::Mat(h, w, CV_32FC1, const_cast<float*>(img.data())));
      cam.emit(&run.events, &run.labels);
    }
    return run;
  };
  EventCamera cam(w, h, noisy(), 99);
  EventRun ref;
  cam.update(0, frameAt(w, h, 0).data(), &ref.events, &ref.labels);
  for (int k = 1; k <= 60; ++k) {
    const auto img = frameAt(w, h, k);
    std::vector<std::uint32_t> idx;
    std::vector<float> val;
    for (const cv::Rect& r : subset(k))
      for (int y = r.y; y < r.y + r.height; ++y)
        for (int x = r.x; x < r.x + r.width; ++x) {
          idx.push_back(static_cast<std::uint32_t>(y * w + x));
          val.push_back(img[idx.back()]);
        }
    cam.updatePixels(k * 500'000, idx.data(), val.data(), idx.size());
    cam.emit(&ref.events, &ref.labels);
  }
  ASSERT_GT(ref.events.size(), 1000u);
  for (const int threads : {1, 2}) {
    const EventRun a = runRects(threads);
    EXPECT_TRUE(a.events == ref.events) << threads;
    EXPECT_TRUE(a.labels == ref.labels) << threads;
  }
  // Bad input changes nothing: overlapping or outside rectangles, a pixel not after its last sample.
  const cv::Mat img(h, w, CV_32FC1, cv::Scalar(1.0f));
  const std::uint64_t updates = cam.pixelUpdates();
  EXPECT_THROW(cam.updateRects(40'000'000, {cv::Rect(0, 0, 16, 16), cv::Rect(8, 8, 16, 16)}, img), Error);
  EXPECT_THROW(cam.updateRects(40'000'000, {cv::Rect(w - 8, 0, 16, 16)}, img), Error);
  EXPECT_THROW(cam.updateRects(30'000'000, {cv::Rect(0, 0, 16, 16)}, img), Error);  // every tile is at 30 ms
  EXPECT_EQ(cam.pixelUpdates(), updates);
}

TEST(EventCamera, PerPixelSamplesAreEmittedUpToTheWatermark) {
  EventCamera cam(2, 1, ideal(), 1);
  const std::vector<float> start = {radianceOfLog(0.0), radianceOfLog(0.0)};
  EventArray ev;
  std::vector<EventLabel> labels;
  cam.update(0, start.data(), &ev, &labels);
  // Pixel 0 jumps by 1.05 (5 events in (0, 10 ms]); pixel 1 is only sampled at 2 ms.
  cam.updatePixel(0, 10 * kNsPerMs, radianceOfLog(1.05));
  cam.updatePixel(1, 2 * kNsPerMs, radianceOfLog(0.0));
  EXPECT_EQ(cam.emit(&ev, &labels), 2 * kNsPerMs);
  ASSERT_EQ(ev.size(), 1u);  // the event at 1.9 ms; the others wait
  EXPECT_NEAR(static_cast<double>(ev[0].t_ns), 0.2 / 1.05 * 10e6, 1000.0);
  EXPECT_EQ(cam.pendingCount(), 4u);
  cam.updatePixel(1, 20 * kNsPerMs, radianceOfLog(0.0));
  EXPECT_EQ(cam.emit(&ev, &labels), 10 * kNsPerMs);
  EXPECT_EQ(ev.size(), 5u);
  EXPECT_EQ(cam.pendingCount(), 0u);
  EXPECT_THROW(cam.updatePixel(0, 10 * kNsPerMs, 1.0f), Error);  // not after its last sample
  EXPECT_THROW(cam.update(15 * kNsPerMs, start.data(), &ev, &labels), Error);  // pixel 1 is at 20 ms
  EXPECT_EQ(cam.pixelUpdates(), 5u);  // 2 at initialisation + 3 accepted samples
}

TEST(EventCamera, OptionsAreValidated) {
  EventCamera::Options o;
  o.threshold_pos = 0.0;
  EXPECT_THROW(o.validate(), Error);
  o = {};
  o.cutoff_max_hz = 10.0;
  o.cutoff_min_hz = 20.0;
  EXPECT_THROW(o.validate(), Error);
  o = {};
  o.hot_pixel_fraction = 1.5;
  EXPECT_THROW(EventCamera(4, 4, o, 1), Error);
}

TEST(EventCamera, AbsurdRatesAreOneErrorNamingTheField) {  // issue 19: every rate bounded
  struct Case {
    const char* field;
    double EventCamera::Options::*member;
    double largest;
  };
  for (const Case& c : {Case{"leak_rate_hz", &EventCamera::Options::leak_rate_hz, 1e4},
                        Case{"shot_noise_rate_hz", &EventCamera::Options::shot_noise_rate_hz, 1e4},
                        Case{"hot_pixel_rate_hz", &EventCamera::Options::hot_pixel_rate_hz, 1e4},
                        Case{"cutoff_max_hz", &EventCamera::Options::cutoff_max_hz, 1e6}}) {
    EventCamera::Options o;
    o.*c.member = c.largest;
    EXPECT_NO_THROW(o.validate()) << c.field;
    o.*c.member = 1e12;
    try {
      o.validate();
      ADD_FAILURE() << c.field << " = 1e12 accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(c.field), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace evio::simulator

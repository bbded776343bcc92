// Event camera noise and low light against their parameters: leak, shot and
// hot-pixel rates within 10 % over long fixed-seed runs; the photoreceptor
// low-pass equals its closed-form solution, so events lag and thin out in
// the dark; the sensor presets load and validate.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "evio/core/error.h"
#include "evio/simulator/event_camera.h"
#include "evio/simulator/event_sensor_preset.h"

namespace evio::simulator {
namespace {

constexpr double kEps = 1e-3;

float radianceOfLog(double l) { return static_cast<float>(std::exp(l) - kEps); }

struct Counts {
  std::vector<std::size_t> per_pixel;
  std::size_t on = 0, total = 0;
};

/// Runs a static image for `seconds` in steps of `step_ns`; counts events of `label`.
Counts runStatic(EventCamera& cam, const std::vector<float>& img, double seconds, TimeNs step_ns,
                 EventLabel label) {
  Counts c;
  c.per_pixel.assign(cam.pixelCount(), 0);
  EventArray ev;
  std::vector<EventLabel> labels;
  const auto steps = static_cast<std::int64_t>(std::llround(seconds * 1e9 / static_cast<double>(step_ns)));
  for (std::int64_t k = 0; k <= steps; ++k) {
    ev.clear();
    labels.clear();
    cam.update(k * step_ns, img.data(), &ev, &labels);
    for (std::size_t i = 0; i < ev.size(); ++i) {
      if (labels[i] != label) continue;
      ++c.per_pixel[static_cast<std::size_t>(ev[i].y) * static_cast<std::size_t>(cam.width()) + ev[i].x];
      ++c.total;
      c.on += ev[i].positive ? 1 : 0;
    }
  }
  return c;
}

TEST(EventNoise, LeakRateMatchesItsParameter) {
  EventCamera::Options o;
  o.leak_rate_hz = 0.2;
  EventCamera cam(100, 100, o, 21);
  const std::vector<float> img(10000, 3.0f);
  const Counts c = runStatic(cam, img, 50.0, 10 * kNsPerMs, EventLabel::kLeak);
  const double expected = 0.2 * 10000 * 50.0;  // 100 000 events, Poisson sd 0.3 %
  EXPECT_NEAR(static_cast<double>(c.total), expected, 0.10 * expected);
  EXPECT_EQ(c.on, c.total);  // leak events are ON
  // Per-pixel counts are Poisson(10): variance = mean within 10 %.
  double mean = 0.0, var = 0.0;
  for (const auto n : c.per_pixel) mean += static_cast<double>(n);
  mean /= 10000.0;
  for (const auto n : c.per_pixel) var += (static_cast<double>(n) - mean) * (static_cast<double>(n) - mean);
  var /= 9999.0;
  EXPECT_NEAR(var / mean, 1.0, 0.10);
}

TEST(EventNoise, ShotNoiseRateRisesInTheDarkAsStated) {
  // r(I) = R (1 − (1 − b) I / (I + I_ref)): three columns of pixels at
  // I = 0, I_ref and 100 I_ref.
  EventCamera::Options o;
  o.shot_noise_rate_hz = 5.0;
  o.shot_noise_bright_factor = 0.25;
  o.reference_radiance_w_m2_sr = 2.0;
  const int w = 60, h = 50;
  EventCamera cam(w, h, o, 8);
  const float radiance[3] = {0.0f, 2.0f, 200.0f};
  std::vector<float> img(static_cast<std::size_t>(w * h));
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) img[static_cast<std::size_t>(y * w + x)] = radiance[x / 20];
  const double seconds = 60.0;
  const Counts c = runStatic(cam, img, seconds, 5 * kNsPerMs, EventLabel::kShot);
  for (int band = 0; band < 3; ++band) {
    const double iv = static_cast<double>(radiance[band]);
    const double rate = 5.0 * (1.0 - 0.75 * iv / (iv + 2.0));
    std::size_t n = 0;
    for (int y = 0; y < h; ++y)
      for (int x = band * 20; x < band * 20 + 20; ++x) n += c.per_pixel[static_cast<std::size_t>(y * w + x)];
    const double expected = rate * 1000.0 * seconds;
    EXPECT_NEAR(static_cast<double>(n), expected, 0.10 * expected) << "I = " << iv;
  }
  EXPECT_NEAR(static_cast<double>(c.on) / static_cast<double>(c.total), 0.5, 0.02);
}

TEST(EventNoise, ShotNoiseDoesNotDependOnTheSampleStep) {
  // The per-pixel hazard is exact for piecewise-constant rates: 1 ms and
  // 20 ms steps give the same events.
  EventCamera::Options o;
  o.shot_noise_rate_hz = 20.0;
  const std::vector<float> img(400, 0.0f);
  EventCamera fine(20, 20, o, 3), coarse(20, 20, o, 3);
  EventArray ef, ec;
  std::vector<EventLabel> lf, lc;
  for (int k = 0; k <= 2000; ++k) fine.update(k * kNsPerMs, img.data(), &ef, &lf);
  for (int k = 0; k <= 100; ++k) coarse.update(k * 20 * kNsPerMs, img.data(), &ec, &lc);
  ASSERT_GT(ef.size(), 10000u);
  ASSERT_EQ(ef.size(), ec.size());
  // Per pixel: the same events, times within 2 µs (float hazards).
  const auto perPixel = [](const EventArray& e) {
    std::vector<std::vector<Event>> out(400);
    for (std::size_t i = 0; i < e.size(); ++i) out[static_cast<std::size_t>(e[i].y * 20 + e[i].x)].push_back(e[i]);
    return out;
  };
  const auto pf = perPixel(ef), pc = perPixel(ec);
  for (std::size_t p = 0; p < 400; ++p) {
    ASSERT_EQ(pf[p].size(), pc[p].size()) << p;
    for (std::size_t k = 0; k < pf[p].size(); ++k) {
      EXPECT_EQ(pf[p][k].positive, pc[p][k].positive);
      EXPECT_NEAR(static_cast<double>(pf[p][k].t_ns), static_cast<double>(pc[p][k].t_ns), 2000.0);
    }
  }
}

TEST(EventNoise, HotPixelsAreTheStatedFractionAndRate) {
  EventCamera::Options o;
  o.hot_pixel_fraction = 0.005;
  o.hot_pixel_rate_hz = 80.0;
  EventCamera cam(100, 80, o, 12);  // 8000 pixels → 40 hot
  std::size_t hot = 0;
  for (std::size_t i = 0; i < cam.pixelCount(); ++i) hot += cam.isHot(i) ? 1 : 0;
  ASSERT_EQ(hot, 40u);
  const std::vector<float> img(8000, 1.0f);
  const Counts c = runStatic(cam, img, 30.0, 10 * kNsPerMs, EventLabel::kHot);
  const double expected = 40 * 80.0 * 30.0;
  EXPECT_NEAR(static_cast<double>(c.total), expected, 0.10 * expected);
  for (std::size_t i = 0; i < cam.pixelCount(); ++i) {
    if (!cam.isHot(i)) {
      ASSERT_EQ(c.per_pixel[i], 0u) << i;
    } else {
      EXPECT_NEAR(static_cast<double>(c.per_pixel[i]), 80.0 * 30.0, 0.10 * 80.0 * 30.0) << i;
    }
  }
}

TEST(EventNoise, PhotoreceptorLowPassMatchesTheClosedForm) {
  // A step of L from l_a to l_b, ramped over the first 0.1 ms sample
  // interval, then constant: L_f(t1) = l_b − (l_b − l_a) φ(x1), then
  // L_f(t) = l_b + (L_f(t1) − l_b) e^(−(t − t1)/τ), τ = 1/(2π f_c(I_b)).
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.0;
  o.cutoff_max_hz = 300.0;
  o.cutoff_min_hz = 2.0;
  o.reference_radiance_w_m2_sr = 1.0;
  const double la[2] = {std::log(kEps + 10.0), std::log(kEps + 0.01)};  // bright, dark
  EventCamera cam(2, 1, o, 4);
  EventArray ev;
  std::vector<EventLabel> labels;
  const std::vector<float> start = {radianceOfLog(la[0]), radianceOfLog(la[1])};
  cam.update(0, start.data(), &ev, &labels);
  const std::vector<float> stepped = {radianceOfLog(la[0] + 1.0), radianceOfLog(la[1] + 1.0)};
  const TimeNs dt = 100'000;
  double tau[2], lf1[2];
  for (int p = 0; p < 2; ++p) {
    const double ib = std::exp(la[p] + 1.0) - kEps;
    tau[p] = 1.0 / (2.0 * std::numbers::pi * (2.0 + 298.0 * ib / (ib + 1.0)));
    const double x = 1e-4 / tau[p];
    lf1[p] = la[p] + 1.0 - (1.0 - std::exp(-x)) / x;
  }
  TimeNs first[2] = {-1, -1};
  for (int k = 1; k <= 400; ++k) {  // 40 ms
    cam.update(k * dt, stepped.data(), &ev, &labels);
    for (int p = 0; p < 2; ++p) {
      const double t = static_cast<double>(k - 1) * 1e-4;
      const double expected = la[p] + 1.0 + (lf1[p] - la[p] - 1.0) * std::exp(-t / tau[p]);
      ASSERT_NEAR(static_cast<double>(cam.filteredLog(static_cast<std::size_t>(p))), expected, 2e-5) << p << " " << k;
    }
  }
  for (std::size_t i = 0; i < ev.size(); ++i)
    if (first[ev[i].x] < 0) first[ev[i].x] = ev[i].t_ns;
  // Bright: τ ≈ 0.58 ms, first event (L_f up by 0.2) after ≈ τ ln(1/0.8) ≈ 0.13 ms;
  // dark: τ ≈ 16 ms, ≈ 3.6 ms: events lag in the dark. (The step's ramp over
  // the first 0.1 ms delays both by ≈ 0.05 ms.)
  ASSERT_GT(first[0], 0);
  ASSERT_GT(first[1], 0);
  EXPECT_NEAR(static_cast<double>(first[0]), -tau[0] * std::log(0.8) * 1e9, 0.1 * 1e6);
  EXPECT_NEAR(static_cast<double>(first[1]), -tau[1] * std::log(0.8) * 1e9, 0.1 * 1e6);
  EXPECT_GT(first[1], 10 * first[0]);
}

TEST(EventNoise, ShortPulsesVanishInTheDark) {
  // A 2 ms pulse of +1.0 in L: the bright pixel follows it (≥ 3 ON and OFF
  // events); the dark pixel's filter rises by ≈ 0.1 < C, so no event at all.
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.0;
  o.cutoff_max_hz = 300.0;
  const double la[2] = {std::log(kEps + 10.0), std::log(kEps + 0.01)};
  EventCamera cam(2, 1, o, 4);
  EventArray ev;
  std::vector<EventLabel> labels;
  for (int k = 0; k <= 300; ++k) {  // 30 ms at 0.1 ms, pulse in [5, 7) ms
    const double up = (k >= 50 && k < 70) ? 1.0 : 0.0;
    const std::vector<float> img = {radianceOfLog(la[0] + up), radianceOfLog(la[1] + up)};
    cam.update(k * 100'000, img.data(), &ev, &labels);
  }
  std::size_t on[2] = {0, 0}, off[2] = {0, 0};
  for (std::size_t i = 0; i < ev.size(); ++i) (ev[i].positive ? on : off)[ev[i].x]++;
  EXPECT_GE(on[0], 3u);
  EXPECT_GE(off[0], 3u);
  EXPECT_EQ(on[1] + off[1], 0u);
}

TEST(EventSensorPresets, LoadAndValidate) {
  const std::string dir = EVIO_SIMULATOR_PRESET_DIR;
  const EventSensorPreset d240 = loadEventSensorPreset(dir + "/davis240c.yaml");
  EXPECT_EQ(d240.width, 240);
  EXPECT_EQ(d240.height, 180);
  const EventSensorPreset d346 = loadEventSensorPreset(dir + "/davis346.yaml");
  EXPECT_EQ(d346.width, 346);
  EXPECT_EQ(d346.height, 260);
  const EventSensorPreset dvx = loadEventSensorPreset(dir + "/dvxplorer.yaml", {"event_camera.leak_rate_hz=0.3"});
  EXPECT_EQ(dvx.width, 640);
  EXPECT_EQ(dvx.height, 480);
  EXPECT_DOUBLE_EQ(dvx.event_camera.leak_rate_hz, 0.3);
  for (const auto* p : {&d240, &d346, &dvx}) {
    EXPECT_GT(p->event_camera.photoreceptorCutoffHz(1.0), 0.0) << p->name;  // every preset is band-limited
    EXPECT_GT(p->event_camera.leak_rate_hz + p->event_camera.shot_noise_rate_hz, 0.0) << p->name;
    EXPECT_NO_THROW(EventCamera(p->width, p->height, p->event_camera, 1)) << p->name;
  }
  EXPECT_THROW(loadEventSensorPreset(dir + "/davis240c.yaml", {"event_camera.threshold_pos=-1"}), Error);
  EXPECT_THROW(loadEventSensorPreset(dir + "/davis240c.yaml", {"event_camera.no_such_key=1"}), Error);
}

}  // namespace
}  // namespace evio::simulator

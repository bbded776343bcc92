// The DVS pixel of issue 17 against analytic values: the photocurrent of the
// camera equation; the photoreceptor's step response, whose time constant is
// 1/(2π κ I_ph) at two light levels; the source follower in cascade; the
// same-pixel intervals a refractory period leaves on a known ramp; events per
// edge crossing; the ON fraction C⁻/(C⁺ + C⁻) of a periodic signal; the
// background-activity filter rule and its pass rate on Poisson noise; the
// shot-noise rate against photocurrent; thread-count independence with every
// new stage on; the DAVIS240C presets.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "evio/core/error.h"
#include "evio/simulator/background_activity_filter.h"
#include "evio/simulator/event_camera.h"
#include "evio/simulator/event_sensor_preset.h"

namespace evio::simulator {
namespace {

/// A photocurrent pixel with round numbers: N = 2, T = 1, A = 100 µm²,
/// QE = 0.5, λ = 500 nm, so k = q·QE·A·λ/(hc)·π/(4N²) = 3.9592 pA per W/(m²·sr)
/// (1.602177e-19 C · 0.5 · 1e-10 m² · 2.51705e18 /J · 0.1963495, by hand).
EventCamera::Options photocurrentPixel() {
  EventCamera::Options o;
  o.bandwidth_model = "photocurrent";
  o.f_number = 2.0;
  o.lens_transmission = 1.0;
  o.photodiode_area_um2 = 100.0;
  o.quantum_efficiency = 0.5;
  o.wavelength_nm = 500.0;
  o.dark_current_fa = 1.0;
  o.photoreceptor_hz_per_pa = 1000.0;
  o.threshold_mismatch_sigma = 0.0;
  return o;
}
constexpr double kPaPerRadiance = 3.95916;

/// Times of the events of pixel x in `ev`, s.
std::vector<double> timesOf(const EventArray& ev, int x) {
  std::vector<double> t;
  for (std::size_t i = 0; i < ev.size(); ++i)
    if (ev[i].x == x) t.push_back(static_cast<double>(ev[i].t_ns) * 1e-9);
  return t;
}

TEST(EventPixel, PhotocurrentFollowsTheCameraEquation) {
  const EventCamera::Options o = photocurrentPixel();
  EXPECT_NEAR(o.photocurrentPerRadiancePa(), kPaPerRadiance, 1e-4);
  // ε = I_dark / k: the log input is log(I_ph + I_dark) up to a constant.
  EXPECT_NEAR(o.logEpsilon(), 1e-3 / kPaPerRadiance, 1e-8);
  // f_c = κ (k I + I_dark): 1000 Hz/pA · (3.9598 + 0.001) pA at 1 W/(m² sr).
  EXPECT_NEAR(o.photoreceptorCutoffHz(1.0), 1000.0 * (kPaPerRadiance + 1e-3), 0.1);
}

TEST(EventPixel, StepResponseTimeConstantIsInverseToPhotocurrent) {
  // Two pixels stepped by ΔL = +1.1 (a factor e^1.1 in photocurrent) to
  // 0.1 pA and 1 pA. The photoreceptor alone (no source follower) is one
  // pole, L_f(t) = L_0 + ΔL (1 − e^(−t/τ)), τ = 1/(2π κ I_ph(after)), so
  // event k (threshold C = 0.2) fires at t_k = −τ ln(1 − k C / ΔL), k = 1…5.
  const EventCamera::Options o = photocurrentPixel();
  const double delta = 1.1, c = 0.2;
  const double target_pa[2] = {0.1, 1.0};
  std::vector<float> before(2), after(2);
  double tau[2];
  for (int p = 0; p < 2; ++p) {
    const double i_after = target_pa[p] - 1e-3;  // photocurrent without the dark current
    after[p] = static_cast<float>(i_after / kPaPerRadiance);
    before[p] = static_cast<float>(((i_after + 1e-3) * std::exp(-delta) - 1e-3) / kPaPerRadiance);
    tau[p] = 1.0 / (2.0 * std::numbers::pi * 1000.0 * target_pa[p]);
  }
  EventCamera cam(2, 1, o, 3);
  EventArray ev;
  cam.update(0, before.data(), &ev, nullptr);
  const TimeNs step = 2'000;  // 2 µs samples; the step itself is a ramp over the first one
  for (int k = 1; k <= 10'000; ++k) cam.update(k * step, after.data(), &ev, nullptr);  // 20 ms
  for (int p = 0; p < 2; ++p) {
    const std::vector<double> t = timesOf(ev, p);
    ASSERT_EQ(t.size(), 5u) << p;
    for (int k = 1; k <= 5; ++k) {
      const double expected = -tau[p] * std::log(1.0 - k * c / delta) + 1e-6;  // + half the ramp
      EXPECT_NEAR(t[static_cast<std::size_t>(k - 1)], expected, 0.01 * expected + 2e-6) << p << " k=" << k;
    }
  }
  // The dark pixel lags ten times longer: the ratio of photocurrents.
  const std::vector<double> dark = timesOf(ev, 0), bright = timesOf(ev, 1);
  EXPECT_NEAR(dark[2] / bright[2], 10.0, 0.15);
}

TEST(EventPixel, SourceFollowerCascadesASecondPole) {
  // Photoreceptor pole a = 2π f_pr and source follower b = 2π f_sf in series:
  // the unit step response is 1 − (a e^(−bt) − b e^(−at)) / (a − b).
  EventCamera::Options o = photocurrentPixel();
  o.source_follower_hz = 300.0;
  o.threshold_pos = o.threshold_neg = 5.0;  // no events; watch L_f itself
  const float before = 1.0f, after = static_cast<float>(std::exp(1.0) * (1.0 + o.logEpsilon()) - o.logEpsilon());
  const double a = 2.0 * std::numbers::pi * o.photoreceptorCutoffHz(after);
  const double b = 2.0 * std::numbers::pi * 300.0;
  EventCamera cam(1, 1, o, 1);
  cam.update(0, &before, nullptr, nullptr);
  const double l0 = cam.filteredLog(0);
  const TimeNs step = 1'000;
  for (int k = 1; k <= 10'000; ++k) {  // 10 ms
    cam.update(k * step, &after, nullptr, nullptr);
    const double t = static_cast<double>(k * step) * 1e-9 - 0.5e-6;  // the first sample ramps the step
    const double expected = 1.0 - (a * std::exp(-b * t) - b * std::exp(-a * t)) / (a - b);
    ASSERT_NEAR(static_cast<double>(cam.filteredLog(0)) - l0, expected, 2e-3) << k;
  }
}

TEST(EventPixel, RefractoryPeriodLeavesMultiplesOfTheCrossingPeriod) {
  // Ideal pixels (no filter) on log ramps crossing C = 0.1 every p = C/s;
  // with refractory R each emitted interval is the smallest multiple of p
  // not below R: p = 1 ms, R = 2.5 ms → 3 ms; p = 0.5 ms, R = 1.66 ms → 2 ms.
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.0;
  o.threshold_pos = o.threshold_neg = 0.1;
  const double slope[2] = {100.0, 200.0};  // log units per s
  const double refractory[2] = {2.5e-3, 1.66e-3};
  const double expected[2] = {3e-3, 2e-3};
  for (int p = 0; p < 2; ++p) {
    o.refractory_period_s = refractory[p];
    EventCamera cam(1, 1, o, 1);
    EventArray ev;
    const double eps = o.logEpsilon();
    for (int k = 0; k <= 1400; ++k) {  // 0.098 s in 0.07 ms steps (crossings fall between samples)
      const float v = static_cast<float>(std::exp(slope[p] * k * 7e-5) - eps);
      cam.update(k * 70'000, &v, &ev, nullptr);
    }
    const std::vector<double> t = timesOf(ev, 0);
    ASSERT_GT(t.size(), 20u);
    for (std::size_t i = 1; i < t.size(); ++i) {
      EXPECT_GE(t[i] - t[i - 1], refractory[p]);
      EXPECT_NEAR(t[i] - t[i - 1], expected[p], 2e-6) << p << " " << i;
    }
  }
}

TEST(EventPixel, RefractoryMismatchIsLogNormalPerPixel) {
  // R_i = R exp(σ z_i): over 40 000 pixels the median of R_i is R and the
  // standard deviation of ln(R_i / R) is σ, each within 2 %.
  EventCamera::Options o;
  o.refractory_period_s = 0.002;
  o.refractory_mismatch_sigma = 0.2;
  EventCamera cam(200, 200, o, 3);
  std::vector<double> logs;
  for (std::size_t i = 0; i < cam.pixelCount(); ++i)
    logs.push_back(std::log(static_cast<double>(cam.refractoryNs(i)) / 2e6));
  double mean = 0.0, var = 0.0;
  for (const double l : logs) mean += l;
  mean /= static_cast<double>(logs.size());
  for (const double l : logs) var += (l - mean) * (l - mean);
  std::nth_element(logs.begin(), logs.begin() + static_cast<std::ptrdiff_t>(logs.size() / 2), logs.end());
  EXPECT_NEAR(std::exp(logs[logs.size() / 2]), 1.0, 0.02);
  EXPECT_NEAR(std::sqrt(var / static_cast<double>(logs.size())), 0.2, 0.004);
}

TEST(EventPixel, EventsPerEdgeCrossingAreTheContrastOverTheThreshold) {
  // An edge of log contrast ΔL = 0.95 passes a band-limited pixel and back:
  // floor(ΔL / C⁺) ON events up, then floor((r − L_0) / C⁻) OFF events down,
  // whatever the bandwidth (the filter is monotone for a step).
  EventCamera::Options o = photocurrentPixel();
  o.source_follower_hz = 500.0;
  o.threshold_pos = 0.3;
  o.threshold_neg = 0.2;
  const float dark = 0.05f, bright = static_cast<float>((0.05 + o.logEpsilon()) * std::exp(0.95) - o.logEpsilon());
  EventCamera cam(1, 1, o, 1);
  EventArray ev;
  int k = 0;
  for (; k <= 200; ++k) cam.update(k * 100'000, k < 10 ? &dark : &bright, &ev, nullptr);   // 20 ms up
  for (; k <= 600; ++k) cam.update(k * 100'000, &dark, &ev, nullptr);                       // 40 ms down
  std::size_t on = 0, off = 0;
  for (std::size_t i = 0; i < ev.size(); ++i) (ev[i].positive ? on : off)++;
  EXPECT_EQ(on, 3u);   // floor(0.95 / 0.3): r rises 0.9
  EXPECT_EQ(off, 4u);  // floor(0.9 / 0.2)
}

TEST(EventPixel, OnFractionIsTheThresholdRatioOverAPeriodicSignal) {
  // L oscillates (amplitude 2, 100 cycles): the total rise equals the total
  // fall, so N_on C⁺ ≈ N_off C⁻ and the ON fraction → C⁻ / (C⁺ + C⁻) = 0.4.
  EventCamera::Options o;
  o.threshold_mismatch_sigma = 0.0;
  o.threshold_pos = 0.3;
  o.threshold_neg = 0.2;
  EventCamera cam(1, 1, o, 1);
  EventArray ev;
  for (int k = 0; k <= 100'000; ++k) {  // 100 s at 1 ms, 1 Hz
    const float v = static_cast<float>(std::exp(2.0 * std::sin(2.0 * std::numbers::pi * k * 1e-3)));
    cam.update(TimeNs{k} * 1'000'000, &v, &ev, nullptr);
  }
  std::size_t on = 0;
  for (std::size_t i = 0; i < ev.size(); ++i) on += ev[i].positive ? 1 : 0;
  ASSERT_GT(ev.size(), 2000u);
  EXPECT_NEAR(static_cast<double>(on) / static_cast<double>(ev.size()), 0.4, 0.002);
}

TEST(BackgroundActivityFilter, PassesSupportedEventsAndDropsIsolatedOnes) {
  BackgroundActivityFilter f(10, 10, 20 * kNsPerMs);
  EXPECT_FALSE(f.pass(5, 5, 0));                 // isolated: nothing before it
  EXPECT_TRUE(f.pass(6, 5, 10 * kNsPerMs));      // a neighbour fired 10 ms before
  EXPECT_TRUE(f.pass(5, 5, 25 * kNsPerMs));      // supported by (6, 5) at 10 ms, 15 ms before
  EXPECT_FALSE(f.pass(0, 0, 26 * kNsPerMs));     // far from every event
  EXPECT_FALSE(f.pass(6, 5, 60 * kNsPerMs));     // its neighbours last fired 35 ms before: > T
  EXPECT_FALSE(f.pass(6, 5, 61 * kNsPerMs));     // its own event does not support it
  EXPECT_TRUE(f.pass(7, 6, 61 * kNsPerMs));      // diagonal neighbour of (6, 5)
  EXPECT_FALSE(f.pass(1, 0, 62 * kNsPerMs));     // (0, 0) fired 36 ms before: > T
  EXPECT_TRUE(f.pass(0, 0, 63 * kNsPerMs));      // a corner pixel, supported by (1, 0) 1 ms before
}

TEST(BackgroundActivityFilter, PassRateOnPoissonNoiseIsTheSupportProbability) {
  // Leak noise at r per pixel: an interior event passes iff one of its 8
  // neighbours fired within T before it, P = 1 − e^(−8 r T). r = 5 Hz,
  // T = 20 ms: passed rate r P = 2.753 Hz per interior pixel; 58² interior
  // pixels over 20 s expect 185 000 events (Poisson sd 0.23 %); within 2 %.
  EventCamera::Options o;
  o.leak_rate_hz = 5.0;
  o.ba_filter_window_s = 0.02;
  const int w = 60, h = 60;
  EventCamera cam(w, h, o, 17);
  const std::vector<float> still(static_cast<std::size_t>(w * h), 1.0f);
  EventArray ev;
  for (int k = 0; k <= 200; ++k) cam.update(k * 100 * kNsPerMs, still.data(), &ev, nullptr);
  std::size_t interior = 0;
  for (std::size_t i = 0; i < ev.size(); ++i)
    interior += (ev[i].x > 0 && ev[i].x < w - 1 && ev[i].y > 0 && ev[i].y < h - 1) ? 1 : 0;
  const double expected = 5.0 * (1.0 - std::exp(-8.0 * 5.0 * 0.02)) * 58.0 * 58.0 * 20.0;
  EXPECT_NEAR(static_cast<double>(interior), expected, 0.02 * expected);
  EXPECT_GT(cam.baDropped(), 0u);
}

TEST(EventPixel, ShotNoiseRateFollowsThePhotocurrent) {
  // r = R (1 − (1 − b) I_ph / (I_ph + I_ref)); at I_ph = I_ref = 1 pA,
  // R = 2 Hz, b = 0.25: 1.25 Hz. 50×50 pixels over 40 s: 125 000 events
  // expected (Poisson sd 0.3 %); within 2 %.
  EventCamera::Options o = photocurrentPixel();
  o.shot_noise_rate_hz = 2.0;
  o.shot_noise_bright_factor = 0.25;
  o.shot_noise_reference_pa = 1.0;
  const float v = static_cast<float>(1.0 / kPaPerRadiance);
  const std::vector<float> still(2500, v);
  EventCamera cam(50, 50, o, 5);
  EventArray ev;
  for (int k = 0; k <= 400; ++k) cam.update(k * 100 * kNsPerMs, still.data(), &ev, nullptr);
  std::size_t on = 0;
  for (std::size_t i = 0; i < ev.size(); ++i) on += ev[i].positive ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(ev.size()), 125'000.0, 2'500.0);
  EXPECT_NEAR(static_cast<double>(on) / static_cast<double>(ev.size()), 0.5, 0.01);  // both polarities
}

TEST(EventPixel, ShotNoiseObeysTheRefractoryPeriodAsADeadTime) {
  // Shot events reset the pixel, so the refractory period R is a
  // non-paralysable dead time: the emitted rate is r / (1 + r R) and no
  // same-pixel interval is shorter than R. r = 200 Hz (dark), R = 5 ms:
  // 100 Hz; 20×20 pixels over 10 s expect 400 000 events; within 2 %.
  EventCamera::Options o;
  o.shot_noise_rate_hz = 200.0;
  o.refractory_period_s = 0.005;
  const std::vector<float> dark(400, 0.0f);
  EventCamera cam(20, 20, o, 9);
  EventArray ev;
  for (int k = 0; k <= 1000; ++k) cam.update(k * 10 * kNsPerMs, dark.data(), &ev, nullptr);
  EXPECT_NEAR(static_cast<double>(ev.size()), 400'000.0, 8'000.0);
  std::vector<TimeNs> last(400, -1000 * kNsPerMs);
  TimeNs shortest = 1000 * kNsPerMs;
  for (std::size_t i = 0; i < ev.size(); ++i) {
    const std::size_t p = static_cast<std::size_t>(ev[i].y) * 20 + ev[i].x;
    shortest = std::min(shortest, ev[i].t_ns - last[p]);
    last[p] = ev[i].t_ns;
  }
  EXPECT_GE(shortest, 5 * kNsPerMs);
}

TEST(EventPixel, OutputWithEveryStageOnDoesNotDependOnThreads) {
  // A moving sine pattern on 200×180 pixels (> one parallel block) with the
  // photocurrent model, source follower, refractory, shot noise, leak and
  // BA filter: identical streams for 1 and 3 threads, and per pixel.
  const int w = 200, h = 180;
  EventCamera::Options o = photocurrentPixel();
  o.source_follower_hz = 400.0;
  o.refractory_period_s = 1e-3;
  o.shot_noise_rate_hz = 1.0;
  o.leak_rate_hz = 0.5;
  o.ba_filter_window_s = 0.02;
  o.threshold_mismatch_sigma = 0.03;
  const auto frame = [&](int k) {
    std::vector<float> img(static_cast<std::size_t>(w * h));
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        img[static_cast<std::size_t>(y * w + x)] =
            static_cast<float>(0.1 + 0.09 * std::sin(0.2 * x + 0.1 * y + 0.05 * k));
    return img;
  };
  const auto run = [&](int threads, bool per_pixel) {
    EventCamera::Options oo = o;
    oo.threads = threads;
    EventCamera cam(w, h, oo, 7);
    EventArray ev;
    std::vector<EventLabel> labels;
    cam.update(0, frame(0).data(), &ev, &labels);
    for (int k = 1; k <= 80; ++k) {
      const auto img = frame(k);
      if (per_pixel) {
        for (std::size_t i = img.size(); i-- > 0;) cam.updatePixel(i, k * kNsPerMs, img[i]);
        cam.emit(&ev, &labels);
      } else {
        cam.update(k * kNsPerMs, img.data(), &ev, &labels);
      }
    }
    return std::make_pair(ev, labels);
  };
  const auto a = run(1, false), b = run(3, false), c = run(1, true);
  ASSERT_GT(a.first.size(), 1000u);
  EXPECT_TRUE(a.first == b.first);
  EXPECT_TRUE(a.second == b.second);
  EXPECT_TRUE(a.first == c.first);
  EXPECT_TRUE(a.second == c.second);
}

TEST(EventPixel, NewOptionsAreValidated) {
  const auto bad = [](auto edit) {
    EventCamera::Options o = photocurrentPixel();
    edit(o);
    return o;
  };
  EXPECT_THROW(bad([](auto& o) { o.bandwidth_model = "magic"; }).validate(), Error);
  EXPECT_THROW(bad([](auto& o) { o.f_number = 0.1; }).validate(), Error);
  EXPECT_THROW(bad([](auto& o) { o.quantum_efficiency = 1.5; }).validate(), Error);
  EXPECT_THROW(bad([](auto& o) { o.dark_current_fa = 0.0; }).validate(), Error);
  EXPECT_THROW(bad([](auto& o) { o.source_follower_hz = -1.0; }).validate(), Error);
  EXPECT_THROW(bad([](auto& o) { o.ba_filter_window_s = 20.0; }).validate(), Error);
  EXPECT_NO_THROW(photocurrentPixel().validate());
}

TEST(EventSensorPresets, CalibratedAndLegacyDavis240cLoad) {
  const std::string dir = EVIO_SIMULATOR_PRESET_DIR;
  const EventSensorPreset now = loadEventSensorPreset(dir + "/davis240c.yaml");
  const EventSensorPreset old = loadEventSensorPreset(dir + "/davis240c_legacy.yaml");
  EXPECT_TRUE(now.event_camera.photocurrentModel());
  EXPECT_DOUBLE_EQ(now.event_camera.ba_filter_window_s, 0.02);  // libcaer / rpg_dvs_ros default: 80 × 250 µs
  EXPECT_DOUBLE_EQ(now.event_camera.hot_pixel_fraction, 0.0);   // none in the real slice
  EXPECT_FALSE(old.event_camera.photocurrentModel());
  EXPECT_DOUBLE_EQ(old.event_camera.refractory_period_s, 0.0005);
  EXPECT_DOUBLE_EQ(old.event_camera.ba_filter_window_s, 0.0);
  for (const auto* p : {&now, &old}) EXPECT_NO_THROW(EventCamera(p->width, p->height, p->event_camera, 1));
}

}  // namespace
}  // namespace evio::simulator

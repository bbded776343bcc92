// The DAVIS APS model (frame_camera.h, simulator/presets/aps_*.yaml), one
// property per test against its analytic value: the exposure from the
// radiometric chain at a stated illuminance, the black and white clipping
// levels, the fixed-pattern statistics, rolling-shutter row timing, fixed
// exposure against the DAVIS driver's auto-exposure rule, dark current
// against exposure, and frames independent of the thread count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>

#include "evio/core/io/config.h"
#include "evio/simulator/davis_auto_exposure.h"
#include "evio/simulator/frame_camera.h"
#include "evio/simulator/scenario.h"
#include "temp_dir.h"

namespace evio::simulator {
namespace {

constexpr double kPlanck = 6.62607015e-34;
constexpr double kLightSpeed = 299792458.0;
constexpr double kLumensPerWatt550 = 680.0;  // 683 lm/W · V(550 nm), docs/simulation.md

FrameCamera::Options preset(const std::string& name) {
  FrameCamera::Options o;
  config::fill(config::loadFile(std::string(EVIO_SIMULATOR_PRESET_DIR) + "/" + name), "", o);
  return o;
}

FrameCamera::Options noiseless(FrameCamera::Options o) {
  o.shot_noise = false;
  o.read_noise_e = 0.0;
  o.gain_fpn_sigma = 0.0;
  o.offset_fpn_sigma_dn = 0.0;
  return o;
}

cv::Mat constant(int w, int h, float v) { return cv::Mat(h, w, CV_32FC1, cv::Scalar(v)); }

/// Radiance of a Lambertian surface of albedo ρ under E lux: ρ E / (680 π).
double lambertianRadiance(double albedo, double lux) { return albedo * lux / kLumensPerWatt550 / std::numbers::pi; }

double mean(const cv::Mat& m) { return cv::mean(m)[0]; }

double stddev(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  const double mu = mean(d);
  return std::sqrt(cv::mean((d - mu).mul(d - mu))[0]);
}

TEST(ApsModel, ExposureFollowsTheRadiometricChainAtAStatedIlluminance) {
  // White paper (albedo 0.8) under 300 lx, the office light of the ECD
  // analogues, seen by the DAVIS240C for 2 ms.
  FrameCamera::Options o = preset("aps_davis240c.yaml");
  o.exposure_s = 0.002;
  const double radiance = lambertianRadiance(0.8, 300.0);  // 0.1123 W/(m² sr)
  // K = π T p² FF QE λ / (4 N² h c) with the preset's values written out.
  const double k = std::numbers::pi * 0.9 * 18.5e-6 * 18.5e-6 * 0.22 * 0.5 * 550e-9 /
                   (4.0 * 2.0 * 2.0 * kPlanck * kLightSpeed);
  const double electrons = k * radiance * 0.002 + 4700.0 * 0.002;
  const double expected_dn = -16.7 + 131.3 * electrons / 10350.0;
  EXPECT_NEAR(electrons, 4148.0, 2.0);
  EXPECT_NEAR(expected_dn, 35.92, 0.01);
  // Half of the well at 300 lx: 2.50 ms.
  EXPECT_NEAR(0.5 * 10350.0 / (k * radiance), 0.00250, 0.00001);

  FrameCamera ideal(240, 180, noiseless(o), 1);
  EXPECT_NEAR(ideal.electronsPerRadianceSecond(), k, 1e-9 * k);
  EXPECT_NEAR(ideal.idealDn(radiance, 0.002), expected_dn, 1e-9);
  const Frame f = ideal.capture(0, {constant(240, 180, static_cast<float>(radiance))});
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(f.image, &lo, &hi);
  EXPECT_EQ(lo, std::round(expected_dn));
  EXPECT_EQ(hi, std::round(expected_dn));

  // With shot, read and fixed-pattern noise the frame's mean stays there:
  // per pixel σ ≈ 1.8 DN, over 43 200 pixels the mean's σ is 0.009 DN.
  FrameCamera noisy(240, 180, o, 1);
  const Frame g = noisy.capture(0, {constant(240, 180, static_cast<float>(radiance))});
  EXPECT_NEAR(g.mean_dn, expected_dn, 0.05);
}

TEST(ApsModel, ClipsWhiteAtTheFullWellBelowTheAdcRangeAndBlackAtZero) {
  const FrameCamera::Options o = noiseless(preset("aps_davis240c.yaml"));
  FrameCamera cam(64, 48, o, 1);
  // Saturated: the dark offset plus the swing, 114.6 DN (the ECD white level).
  const Frame white = cam.capture(0, {constant(64, 48, 100.0f)});
  EXPECT_EQ(mean(white.image), 115.0);
  EXPECT_EQ(white.saturated_fraction, 1.0);
  // No light: 23 e⁻ of dark current, 0.29 DN above an offset of −16.7 DN: 0.
  const Frame black = cam.capture(0, {constant(64, 48, 0.0f)});
  EXPECT_EQ(mean(black.image), 0.0);
  // The old sensor clips at the ADC's 255.
  FrameCamera legacy(64, 48, noiseless(preset("aps_legacy.yaml")), 1);
  EXPECT_EQ(mean(legacy.capture(0, {constant(64, 48, 1e4f)}).image), 255.0);

  // With fixed-pattern noise the white pile spreads by
  // sqrt((σ_g · 131.3)² + σ_o² + 1/12) = 2.33 DN (the ECD frames: 2.32 DN).
  FrameCamera::Options with_fpn = o;
  with_fpn.gain_fpn_sigma = 0.0146;
  with_fpn.offset_fpn_sigma_dn = 1.3;
  FrameCamera fpn(240, 180, with_fpn, 5);
  const Frame w = fpn.capture(0, {constant(240, 180, 100.0f)});
  const double expected_sigma = std::sqrt(std::pow(0.0146 * 131.3, 2) + 1.3 * 1.3 + 1.0 / 12.0);
  EXPECT_NEAR(w.mean_dn, 114.6, 0.05);
  EXPECT_NEAR(stddev(w.image), expected_sigma, 0.05);
}

TEST(ApsModel, FixedPatternHasTheStatedStatisticsAndDependsOnlyOnTheSeed) {
  FrameCamera::Options o = preset("aps_davis240c.yaml");
  const FrameCamera a(240, 180, o, 11), b(240, 180, o, 11), c(240, 180, o, 12);
  const int n = 240 * 180;
  double sg = 0.0, sg2 = 0.0, so = 0.0, so2 = 0.0;
  int same_seed_equal = 0, other_seed_equal = 0;
  for (int y = 0; y < 180; ++y)
    for (int x = 0; x < 240; ++x) {
      const double g = a.pixelGain(x, y), off = a.pixelOffsetDn(x, y);
      sg += g;
      sg2 += g * g;
      so += off;
      so2 += off * off;
      same_seed_equal += g == b.pixelGain(x, y) && off == b.pixelOffsetDn(x, y);
      other_seed_equal += g == c.pixelGain(x, y);
    }
  const double mg = sg / n, mo = so / n;
  const double sdg = std::sqrt(sg2 / n - mg * mg), sdo = std::sqrt(so2 / n - mo * mo);
  // Means within 4 standard errors (σ/√n), σ within 4 standard errors (σ/√(2n)).
  EXPECT_NEAR(mg, 1.0, 4.0 * 0.0146 / std::sqrt(n));
  EXPECT_NEAR(mo, 0.0, 4.0 * 1.3 / std::sqrt(n));
  EXPECT_NEAR(sdg, 0.0146, 4.0 * 0.0146 / std::sqrt(2.0 * n));
  EXPECT_NEAR(sdo, 1.3, 4.0 * 1.3 / std::sqrt(2.0 * n));
  EXPECT_EQ(same_seed_equal, n);
  EXPECT_EQ(other_seed_equal, 0);
  // Fixed: two noiseless frames of one scene are identical, pixel by pixel.
  FrameCamera quiet(240, 180, [&] {
    FrameCamera::Options q = o;
    q.shot_noise = false;
    q.read_noise_e = 0.0;
    return q;
  }(), 11);
  const cv::Mat scene = constant(240, 180, 0.05f);
  const Frame f1 = quiet.capture(0, {scene}), f2 = quiet.capture(kNsPerMs * 50, {scene});
  EXPECT_EQ(cv::norm(f1.image, f2.image, cv::NORM_INF), 0.0);
  EXPECT_GT(stddev(f1.image), 0.5);
}

TEST(ApsModel, RollingShutterRowsIntegrateTheirOwnWindow) {
  // A scene brightening linearly, L(t) = L0 + α t: every sample of the
  // piecewise-linear interpolation is exact, and row y's mean radiance is
  // L0 + α (y t_row + t_exp / 2).
  const int w = 4, h = 10;
  FrameCamera::Options o = noiseless(preset("aps_legacy.yaml"));
  o.auto_exposure = false;
  o.exposure_s = 0.002;
  o.readout_s = 0.010;  // t_row = 1 ms
  o.full_well_e = 1e8;
  o.shutter = "rolling";
  FrameCamera rolling(w, h, o, 1);
  EXPECT_DOUBLE_EQ(rolling.rowTimeS(), 0.001);
  const double span = rolling.frameSpanS(0.002);
  EXPECT_NEAR(span, 0.011, 1e-15);
  const double l0 = 1.0, alpha = 400.0;  // W/(m² sr) per s
  const double per_radiance = 255.0 * rolling.electronsPerRadianceSecond() * 0.002 / o.full_well_e;
  // Scale so that the brightest row reads about 200 DN.
  const double scale = 200.0 / (per_radiance * (l0 + alpha * 0.010));
  std::vector<cv::Mat> samples;
  const int n = 12;  // every 1 ms over the 11 ms span
  for (int j = 0; j < n; ++j)
    samples.push_back(constant(w, h, static_cast<float>(scale * (l0 + alpha * span * j / (n - 1)))));
  const Frame f = rolling.capture(kNsPerMs, samples);
  EXPECT_EQ(f.t_ns, kNsPerMs + secondsToNs(0.0055));  // the middle of the span
  for (int y = 0; y < h; ++y) {
    const double expected = per_radiance * scale * (l0 + alpha * (y * 0.001 + 0.001));
    for (int x = 0; x < w; ++x) EXPECT_NEAR(f.image.at<std::uint8_t>(y, x), expected, 0.5 + 1e-6) << y;
  }
  // Global shutter with the same samples spread over its own 2 ms: every row alike.
  o.shutter = "global";
  FrameCamera global(w, h, o, 1);
  EXPECT_DOUBLE_EQ(global.frameSpanS(0.002), 0.002);
  std::vector<cv::Mat> gs;
  for (int j = 0; j < 3; ++j) gs.push_back(constant(w, h, static_cast<float>(scale * (l0 + alpha * 0.001 * j))));
  const Frame g = global.capture(0, gs);
  const double expected = per_radiance * scale * (l0 + alpha * 0.001);
  for (int y = 0; y < h; ++y) EXPECT_NEAR(g.image.at<std::uint8_t>(y, 0), expected, 0.5 + 1e-6);
}

TEST(ApsModel, RollingShutterSkewsAMovingEdgeByTheRowTime) {
  // A vertical edge moving right at v = 2000 px/s, bright (L_b) on its left:
  // the pixel centre x is bright from t_x = (x − x0) / v on. Row y exposes
  // [y t_row, y t_row + t_exp], so its bright fraction is
  // clamp((y t_row + t_exp − t_x) / t_exp, 0, 1): the edge in row y lies
  // v · t_row = 1 px further right than in row y − 1. Renders every 50 µs;
  // the interpolation between two renders blurs the crossing by at most
  // half a render interval, 2.5 % of the exposure, 3.2 DN at L_b's 128 DN.
  const int w = 64, h = 16;
  const double t_row = 0.0005, t_exp = 0.002, v = 2000.0, x0 = 10.25;  // crossings between pixel centres
  FrameCamera::Options o = noiseless(preset("aps_legacy.yaml"));
  o.auto_exposure = false;
  o.exposure_s = t_exp;
  o.readout_s = t_row * h;
  o.shutter = "rolling";
  FrameCamera cam(w, h, o, 1);
  const double span = cam.frameSpanS(t_exp);  // 9.5 ms
  const double bright_dn = 128.0;
  const auto l_b = static_cast<float>(bright_dn / 255.0 * o.full_well_e / (cam.electronsPerRadianceSecond() * t_exp));
  std::vector<cv::Mat> samples;
  const int n = static_cast<int>(std::lround(span / 50e-6)) + 1;
  for (int j = 0; j < n; ++j) {
    const double t = span * j / (n - 1);
    cv::Mat m(h, w, CV_32FC1, cv::Scalar(0.0f));
    for (int x = 0; x < w; ++x)
      if (x < x0 + v * t) m.col(x).setTo(cv::Scalar(l_b));
    samples.push_back(m);
  }
  const Frame f = cam.capture(0, samples);
  double worst = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double t_x = (x - x0) / v;
      const double fraction = std::clamp((y * t_row + t_exp - t_x) / t_exp, 0.0, 1.0);
      worst = std::max(worst, std::abs(f.image.at<std::uint8_t>(y, x) - bright_dn * fraction));
    }
  EXPECT_LT(worst, 3.2 + 0.5);  // interpolation bound plus rounding
  // The edge (first pixel below half brightness) moves 1 px per row.
  const auto edge = [&](int y) {
    int x = 0;
    while (x < w && f.image.at<std::uint8_t>(y, x) >= bright_dn / 2) ++x;
    return x;
  };
  for (int y = 1; y < h; ++y) EXPECT_EQ(edge(y) - edge(y - 1), 1) << y;
}

TEST(ApsModel, FixedExposureStaysWhateverTheScene) {
  FrameCamera cam(32, 24, preset("aps_davis240c.yaml"), 1);
  for (const float l : {0.0f, 0.01f, 100.0f}) {
    const Frame f = cam.capture(0, {constant(32, 24, l)});
    EXPECT_EQ(f.exposure_s, 0.005);
    EXPECT_EQ(cam.exposureS(), 0.005);
  }
}

TEST(ApsModel, DavisAutoExposureFollowsTheDriversRule) {
  const auto under_over_step = [](double fraction) {
    return static_cast<std::int64_t>(14000.0 * std::pow(fraction - 0.33, 1.65));
  };
  DavisExposureStatistics s;
  // Under-exposed: all pixels in the lowest tenth.
  s.fraction_low = 1.0;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 5000 + under_over_step(1.0));
  // Over-exposed.
  s.fraction_low = 0.0;
  s.fraction_high = 0.5;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 5000 - under_over_step(0.5));
  // Neither: the mean sample value against 2.5, ⌊100 e²⌋ µs.
  s.fraction_high = 0.0;
  s.mean_sample_value = 1.0;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 5225);
  s.mean_sample_value = 3.0;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 4975);
  s.mean_sample_value = 2.55;  // within the dead band
  EXPECT_EQ(davisNextExposureUs(s, 5000), 5000);
  // Near the under/over limit the step is divided: f_low 0.30 → by 10.
  s.fraction_low = 0.30;
  s.mean_sample_value = 1.5;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 5010);
  // A step that rounds to nothing still moves 1 µs; limits 1 µs and 1 s.
  s.fraction_low = 0.0;
  s.mean_sample_value = 2.6 + 1e-9;
  EXPECT_EQ(davisNextExposureUs(s, 5000), 4999);
  s.fraction_low = 1.0;
  EXPECT_EQ(davisNextExposureUs(s, 999999), 1000000);

  // The statistics of 8-bit frames as the driver sees them (DN · 256).
  cv::Mat frame(10, 10, CV_8UC1, cv::Scalar(24));
  EXPECT_EQ(davisExposureStatistics(frame).fraction_low, 1.0);  // bin 24 < 25
  frame.setTo(cv::Scalar(115));  // the DAVIS240C's white: range 2 of 5, never bin 230
  DavisExposureStatistics white = davisExposureStatistics(frame);
  EXPECT_EQ(white.fraction_low, 0.0);
  EXPECT_EQ(white.fraction_high, 0.0);
  EXPECT_DOUBLE_EQ(white.mean_sample_value, 3.0);

  // Through the camera: a saturated DAVIS240C frame backs off by 25 µs.
  FrameCamera::Options o = preset("aps_davis240c.yaml");
  o.auto_exposure = true;
  FrameCamera cam(32, 24, noiseless(o), 1);
  cam.capture(0, {constant(32, 24, 100.0f)});
  EXPECT_NEAR(cam.exposureS(), 0.004975, 1e-12);
  // A black frame lengthens it by the under-exposure step, within the limit.
  o.auto_exposure_max_s = 0.006;
  FrameCamera dark(32, 24, noiseless(o), 1);
  dark.capture(0, {constant(32, 24, 0.0f)});
  EXPECT_NEAR(dark.exposureS(), 0.006, 1e-12);
}

TEST(ApsModel, DarkCurrentGrowsLinearlyWithExposure) {
  FrameCamera::Options o = preset("aps_davis240c.yaml");
  o.read_noise_e = 0.0;
  o.gain_fpn_sigma = 0.0;
  o.offset_fpn_sigma_dn = 0.0;
  o.dark_offset_dn = 10.0;            // keep the dark signal above the black clip
  o.saturation_dn = 1000.0;           // 0.097 DN per electron: the noise spans several DN
  o.dark_current_e_per_s = 200000.0;  // a hot sensor, to see it in a few ms
  const double dn_per_e = 1000.0 / 10350.0;
  for (const double t : {0.0025, 0.005, 0.010}) {
    o.exposure_s = t;
    FrameCamera cam(240, 180, o, 3);
    const Frame f = cam.capture(0, {constant(240, 180, 0.0f)});
    const double electrons = 200000.0 * t;
    // Mean: offset + the dark electrons (σ of the mean ≤ 0.015 DN);
    // variance: their Poisson variance plus 1/12 of rounding, within 4 %
    // (6 standard errors of a variance over 43 200 pixels).
    EXPECT_NEAR(f.mean_dn, 10.0 + dn_per_e * electrons, 0.06) << t;
    const double sd = stddev(f.image);
    const double expected_var = dn_per_e * dn_per_e * electrons + 1.0 / 12.0;
    EXPECT_NEAR(sd * sd, expected_var, 0.04 * expected_var) << t;
  }
}

TEST(ApsModel, FramesDoNotDependOnTheThreadCount) {
  for (const std::string shutter : {"global", "rolling"}) {
    FrameCamera::Options o = preset("aps_davis240c.yaml");
    o.shutter = shutter;
    std::vector<cv::Mat> samples;
    for (int j = 0; j < 3; ++j) {
      cv::Mat m(180, 240, CV_32FC1);
      for (int y = 0; y < 180; ++y)
        for (int x = 0; x < 240; ++x) m.at<float>(y, x) = 0.02f * static_cast<float>(1 + ((x + 3 * j) / 7 + y / 5) % 9);
      samples.push_back(m);
    }
    o.threads = 1;
    FrameCamera one(240, 180, o, 4);
    o.threads = 3;
    FrameCamera three(240, 180, o, 4);
    for (int k = 0; k < 2; ++k) {
      const Frame a = one.capture(k * kNsPerMs * 46, samples), b = three.capture(k * kNsPerMs * 46, samples);
      ASSERT_EQ(a.image.total(), b.image.total());
      EXPECT_EQ(std::memcmp(a.image.data, b.image.data, a.image.total()), 0) << shutter;
      EXPECT_EQ(a.mean_dn, b.mean_dn);
    }
  }
}

TEST(ApsModel, LegacyPresetIsTheOldLinearModel) {
  const FrameCamera::Options o = preset("aps_legacy.yaml");
  FrameCamera cam(8, 8, noiseless(o), 1);
  EXPECT_EQ(o.auto_exposure_method, "mean_target");
  // DN = round(255 · min(1, K L t / full well)), no offset, no FPN.
  const double k = cam.electronsPerRadianceSecond();
  for (const double l : {0.0, 1.0, 10.0, 40.0}) {
    const double expected = 255.0 * std::min(1.0, k * l * 0.005 / 20000.0);
    EXPECT_NEAR(cam.idealDn(l, 0.005), expected, 1e-9 * (1 + expected)) << l;
  }
  for (const std::string name : {"aps_davis240c.yaml", "aps_davis346.yaml", "aps_legacy.yaml"})
    EXPECT_NO_THROW(preset(name).validate()) << name;
}

TEST(ApsModel, RejectsOptionsOutOfRange) {
  FrameCamera::Options o = preset("aps_davis240c.yaml");
  o.shutter = "diagonal";
  EXPECT_THROW(o.validate(), Error);
  o = preset("aps_davis240c.yaml");
  o.auto_exposure_method = "bright";
  EXPECT_THROW(o.validate(), Error);
  o = preset("aps_davis240c.yaml");
  o.gain_fpn_sigma = -0.1;
  EXPECT_THROW(o.validate(), Error);
  o = preset("aps_davis240c.yaml");
  o.fill_factor = 1.5;
  EXPECT_THROW(o.validate(), Error);
}

TEST(ApsModel, ABadPresetFileIsNamedWithItsLineAndField) {
  const test::TempDir dir;
  const auto errorWith = [&](const std::string& preset_text) {
    std::ofstream(dir.file("aps.yaml")) << preset_text;
    const std::string scenario = "scene: scenes/presets/ec_shapes.yaml\n"
                                 "trajectory: trajectories/presets/hover.yaml\n"
                                 "rig:\n"
                                 "  event_camera: {preset: simulator/presets/davis240c.yaml}\n"
                                 "  frame_camera: {preset: " + dir.file("aps.yaml") + "}\n";
    try {
      loadScenarioString(scenario, "s.yaml", "", {}, EVIO_SOURCE_DIR);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string e = errorWith("exposure_s: 0.005\nfull_wel_e: 10000\n");
  EXPECT_NE(e.find("aps.yaml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("full_wel_e"), std::string::npos) << e;
  e = errorWith("exposure_s: 0.005\nfill_factor: 2\n");
  EXPECT_NE(e.find("fill_factor"), std::string::npos) << e;
  e = errorWith("shutter: [global]\n");
  EXPECT_NE(e.find("aps.yaml:1"), std::string::npos) << e;
}

}  // namespace
}  // namespace evio::simulator

// The frame camera against its radiometric chain: a static scene without
// noise equals the exposure integral exactly; motion blur is the exact
// integral of radiance linear in time; shot and read noise have the stated
// mean and variance; auto-exposure reaches its target; the Mars-yard
// half-shadow view saturates its sunlit part and a lava-tube view is dark
// and noisy; frames do not depend on the thread count.
#include "evio/simulator/frame_camera.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"

namespace evio::simulator {
namespace {

FrameCamera::Options noiseless() {
  FrameCamera::Options o;
  o.auto_exposure = false;
  o.shot_noise = false;
  o.read_noise_e = 0.0;
  return o;
}

cv::Mat constant(int w, int h, float v) { return cv::Mat(h, w, CV_32FC1, cv::Scalar(v)); }

TEST(FrameCamera, RadiometricConstantFollowsTheCameraEquation) {
  const FrameCamera cam(4, 4, FrameCamera::Options{}, 1);
  // K = π T p² QE λ / (4 N² h c) with the defaults.
  const double k = std::numbers::pi * 0.9 * 36e-12 * 0.5 * 550e-9 / (4.0 * 16.0 * 6.62607015e-34 * 299792458.0);
  EXPECT_NEAR(cam.electronsPerRadianceSecond(), k, 1e-9 * k);
  EXPECT_NEAR(cam.electronsPerRadianceSecond(), 2.2e6, 0.05e6);
}

TEST(FrameCamera, StaticSceneEqualsTheExposureIntegral) {
  for (const double gamma : {1.0, 2.2}) {
    FrameCamera::Options o = noiseless();
    o.exposure_s = 0.002;
    o.gamma = gamma;
    const int w = 64, h = 48;
    FrameCamera cam(w, h, o, 3);
    RandomStream rng(9, "test");
    cv::Mat radiance(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) radiance.at<float>(y, x) = static_cast<float>(std::exp(rng.uniform(-6.0, 2.0)));
    // Three identical sub-samples: the trapezoid mean is the radiance itself.
    const Frame f = cam.capture(kNsPerMs, {radiance, radiance, radiance});
    EXPECT_EQ(f.t_start_ns, kNsPerMs);
    EXPECT_EQ(f.t_ns, kNsPerMs + kNsPerMs);  // mid-exposure
    EXPECT_DOUBLE_EQ(f.exposure_s, 0.002);
    const double k = cam.electronsPerRadianceSecond();
    int saturated = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double e = k * static_cast<double>(radiance.at<float>(y, x)) * 0.002;
        const double x01 = std::min(1.0, e / o.full_well_e);
        saturated += e >= o.full_well_e ? 1 : 0;
        ASSERT_EQ(f.image.at<std::uint8_t>(y, x), static_cast<int>(std::round(255.0 * std::pow(x01, 1.0 / gamma))))
            << x << "," << y;
      }
    EXPECT_GT(saturated, 0);
    EXPECT_DOUBLE_EQ(f.saturated_fraction, saturated / static_cast<double>(w * h));
  }
}

TEST(FrameCamera, MotionBlurIsTheExactIntegralOfLinearRadiance) {
  // Radiance linear in time per pixel, L(t) = a + b t over the exposure: the
  // trapezoid rule over any N ≥ 2 sub-samples is exact, mean = a + b T / 2.
  FrameCamera::Options o = noiseless();
  o.exposure_s = 1e-4;
  const int w = 32, h = 8;
  FrameCamera cam(w, h, o, 3);
  const int n = 5;
  std::vector<cv::Mat> subs;
  for (int j = 0; j < n; ++j) {
    cv::Mat m(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) m.at<float>(y, x) = static_cast<float>(2.0 * x + 40.0 * x * j / (n - 1.0) + y);
    subs.push_back(m);
  }
  const Frame f = cam.capture(0, subs);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double mean = 2.0 * x + 20.0 * x + y;
      ASSERT_EQ(f.image.at<std::uint8_t>(y, x), static_cast<int>(std::round(cam.idealDn(mean, 1e-4)))) << x;
    }
}

TEST(FrameCamera, ShotAndReadNoiseHaveTheStatedVariance) {
  // Linear response: DN = 255 n'/FW, n' = Poisson(μ) + N(0, σ_r²); at μ = 20
  // (exact Poisson) and μ = 3000 (Gaussian approximation) the pixel mean and
  // variance in electrons match μ and μ + σ_r² + q²/12 (q = FW/255, quantisation).
  for (const double mu : {20.0, 3000.0}) {
    FrameCamera::Options o;
    o.auto_exposure = false;
    o.exposure_s = 1e-3;
    o.read_noise_e = 5.0;
    o.full_well_e = mu < 100 ? 255.0 : 10000.0;
    const int w = 200, h = 100;
    FrameCamera cam(w, h, o, 17);
    const float radiance = static_cast<float>(mu / (cam.electronsPerRadianceSecond() * 1e-3));
    const Frame f = cam.capture(0, {constant(w, h, radiance)});
    const double q = o.full_well_e / 255.0;
    double sum = 0.0, sum2 = 0.0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double e = f.image.at<std::uint8_t>(y, x) * q;
        sum += e;
        sum2 += e * e;
      }
    const double n = w * h;
    const double mean = sum / n, var = sum2 / n - mean * mean;
    const double expected_var = mu + 25.0 + q * q / 12.0;
    EXPECT_NEAR(mean, mu, 0.02 * mu) << mu;
    EXPECT_NEAR(var, expected_var, 0.10 * expected_var) << mu;
  }
}

TEST(FrameCamera, AutoExposureReachesItsTarget) {
  FrameCamera::Options o;
  o.exposure_s = 1e-5;
  o.auto_exposure_target = 0.4;
  FrameCamera cam(64, 48, o, 5);
  const cv::Mat scene = constant(64, 48, 2.0f);
  Frame f;
  for (int k = 0; k < 8; ++k) f = cam.capture(k * 50 * kNsPerMs, {scene});
  EXPECT_NEAR(f.mean_dn / 255.0, 0.4, 0.02);
  const double expected_exposure = 0.4 * o.full_well_e / (cam.electronsPerRadianceSecond() * 2.0);
  EXPECT_NEAR(f.exposure_s, expected_exposure, 0.05 * expected_exposure);
}

TEST(FrameCamera, HalfShadowViewSaturatesAndLavaTubeIsDarkAndNoisy) {
  // Mars-yard-like view: sunlit sand ≈ 20 W/(m²·sr) with ±40 % albedo
  // texture beside shadow ≈ 1.3 (sunlit/shadow ≈ 16:1). Auto-exposure on
  // the mean leaves a large part of the sunlit side at full well.
  const int w = 120, h = 80;
  cv::Mat yard(h, w, CV_32FC1);
  RandomStream rng(2, "test");
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      yard.at<float>(y, x) = static_cast<float>((x < w / 2 ? 20.0 : 1.3) * rng.uniform(0.6, 1.4));
  FrameCamera cam(w, h, FrameCamera::Options{}, 7);
  Frame f;
  for (int k = 0; k < 10; ++k) f = cam.capture(k * 50 * kNsPerMs, {yard});
  int saturated_sunlit = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w / 2; ++x) saturated_sunlit += f.image.at<std::uint8_t>(y, x) == 255 ? 1 : 0;
  EXPECT_GT(saturated_sunlit, w * h / 2 / 5);  // > 20 % of the sunlit half clips

  // Lava tube: 0.005 W/(m²·sr): exposure pinned at its maximum, image dark,
  // noise a sizeable part of the signal.
  FrameCamera tube_cam(w, h, FrameCamera::Options{}, 7);
  for (int k = 0; k < 10; ++k) f = tube_cam.capture(k * 50 * kNsPerMs, {constant(w, h, 0.005f)});
  EXPECT_DOUBLE_EQ(f.exposure_s, FrameCamera::Options{}.auto_exposure_max_s);
  EXPECT_LT(f.mean_dn, 30.0);
  double sum = 0.0, sum2 = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const double v = f.image.at<std::uint8_t>(y, x);
      sum += v;
      sum2 += v * v;
    }
  const double mean = sum / (w * h), sd = std::sqrt(sum2 / (w * h) - mean * mean);
  EXPECT_GT(sd / mean, 0.05);  // SNR below 20
}

TEST(FrameCamera, FramesDoNotDependOnThreadsAndDifferBetweenFrames) {
  const auto frames = [](int threads) {
    FrameCamera::Options o;
    o.threads = threads;
    FrameCamera cam(97, 61, o, 4);
    std::vector<cv::Mat> out;
    for (int k = 0; k < 3; ++k) out.push_back(cam.capture(k * kNsPerMs * 40, {constant(97, 61, 0.5f)}).image);
    return out;
  };
  const auto a = frames(1), b = frames(2);
  for (int k = 0; k < 3; ++k)
    EXPECT_EQ(std::memcmp(a[static_cast<std::size_t>(k)].data, b[static_cast<std::size_t>(k)].data, 97 * 61), 0);
  EXPECT_NE(std::memcmp(a[1].data, a[2].data, 97 * 61), 0);
}

TEST(FrameCamera, RejectsBadInput) {
  FrameCamera cam(8, 8, FrameCamera::Options{}, 1);
  EXPECT_THROW(cam.capture(0, {}), Error);
  EXPECT_THROW(cam.capture(0, {constant(4, 8, 1.0f)}), Error);
  FrameCamera::Options o;
  o.full_well_e = 0.0;
  EXPECT_THROW(FrameCamera(8, 8, o, 1), Error);
}

}  // namespace
}  // namespace evio::simulator

// The window's still test (pipeline/gyro_bias_window.h, tryStillRest) on
// synthetic inputs with exact truth: 1 kHz IMU readings still for 0.3 s and
// then turning (the rate grows at 20 °/s²), or still throughout, and the
// still probe's frame corners at 20 Hz showing a still camera or one turning
// at 5 °/s. Which combinations the window takes for rest, and where the
// filter then starts.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "evio/core/so3.h"
#include "evio/estimator/pipeline/gyro_bias_window.h"
#include "support/tiny_sequence.h"

namespace evio::estimator {
namespace {

constexpr double kWindowS = 1.0;
const Vec3 kBias(0.03, -0.02, 0.01);  // rad/s

WindowRestTest stillTest() {
  WindowRestTest t;
  t.enabled = true;
  t.gravity_mps2 = 9.81;
  t.noise.accelerometer_noise_density = 0.004316;
  t.noise.gyroscope_noise_density = 2e-4;
  t.prefix.min_s = 0.1;
  return t;
}

/// The prior: the defaults' 6 °/s and 0.3 m/s², a known pose.
Eigen::Matrix<double, 15, 15> prior() {
  Eigen::Matrix<double, 15, 15> P = Eigen::Matrix<double, 15, 15>::Identity() * 1e-8;
  P.block<3, 3>(kIdxBg, kIdxBg) = Mat3::Identity() * std::pow(6.0 * M_PI / 180.0, 2);
  P.block<3, 3>(kIdxBa, kIdxBa) = Mat3::Identity() * 0.09;
  return P;
}

/// Feeds the window 1 kHz readings (level body, gravity along z) still until
/// onset_s and then turning about z with the rate growing at 20 °/s², and,
/// if corners_turn_degps is set, 20 Hz frame corners of a camera turning
/// about its optical axis at that rate (0: still) from t = 0.
GyroBiasEstimate runWindow(GyroBiasWindow& w, double onset_s, std::optional<double> corners_turn_degps) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> unit(0.0, 1.0);
  ImuState x0;
  x0.t_ns = 0;
  w.open(x0);
  const Camera camera = test::tinyCamera();
  const double sg = 2e-4 * std::sqrt(1000.0), sa = 0.004316 * std::sqrt(1000.0);
  for (int k = 0; k <= 1000 && w.collecting(); ++k) {
    const double t = k / 1000.0;
    if (corners_turn_degps && k % 50 == 0) {
      FrameCorners c;
      c.t_ns = secondsToNs(t);
      const Mat3 R = so3::exp(Vec3(0.0, 0.0, *corners_turn_degps * M_PI / 180.0 * t));
      for (int i = 0; i < 20; ++i) {
        const Vec3 p(-0.5 + 0.05 * i, 0.3 * std::sin(i), 1.0);  // static points 1 m ahead
        Vec2 uv;
        if (camera.project(R.transpose() * p, &uv)) c.corners_px.emplace_back(i, uv);
      }
      w.add(c);
    }
    ImuSample s;
    s.t_ns = secondsToNs(t);
    const double rate = t > onset_s ? 20.0 * M_PI / 180.0 * (t - onset_s) : 0.0;
    s.gyro_B = kBias + Vec3(0.0, 0.0, rate) + sg * Vec3(unit(rng), unit(rng), unit(rng));
    s.acc_B = Vec3(0.0, 0.0, 9.81) + sa * Vec3(unit(rng), unit(rng), unit(rng));
    w.add(s);
  }
  return w.estimate(prior());
}

GyroBiasWindow window() { return GyroBiasWindow(kWindowS, 0.1, test::tinyCamera(), Mat3::Identity(), 0, stillTest()); }

TEST(GyroBiasWindowStill, AStillPrefixTheFramesConfirmIsTheRest) {
  GyroBiasWindow w = window();
  const GyroBiasEstimate e = runWindow(w, 0.3, 0.0);
  ASSERT_TRUE(e.at_rest);
  EXPECT_TRUE(e.rest_prefix);
  EXPECT_NEAR(e.rest_s, 0.3, 0.051);  // cut at the onset's block or the next
  EXPECT_EQ(e.rest_image_features, 20);
  ASSERT_TRUE(w.restStart().has_value());
  EXPECT_NEAR(nsToSeconds(w.restStart()->first.t_ns), e.rest_s, 0.002);
  const Vec3 d = e.b_g - kBias;
  EXPECT_LT(d.dot(e.covariance.inverse() * d), 16.3);  // χ²₃ 99.9 %
  // σ: the white noise of 0.3 s (0.021 °/s), the block test's allowance
  // (0.118 °/s) and the images' (the stated 0.1 px on 20 corners over
  // 0.3 s, along the axis they pin worst, the optical axis: here 0.28 °/s in
  // all). Below the tracks' 1–3 °/s, far below the prior's 6.
  const double sigma_degps = std::sqrt(e.covariance(0, 0)) * 180.0 / M_PI;
  EXPECT_GT(sigma_degps, 0.118);
  EXPECT_LT(sigma_degps, 0.5);
}

TEST(GyroBiasWindowStill, APrefixTheFramesSeeTurningIsNot) {
  // The same IMU, but the frames turn at 5 °/s from the first one: a steady
  // turn the IMU would have read as bias.
  GyroBiasWindow w = window();
  const GyroBiasEstimate e = runWindow(w, 0.3, 5.0);
  EXPECT_FALSE(e.at_rest);
  EXPECT_GT(e.rest_image_chi2, 16.27);
  EXPECT_FALSE(w.restStart().has_value());
}

TEST(GyroBiasWindowStill, APrefixTheImagesCannotConfirmIsNotButAWholeStillWindowIs) {
  GyroBiasWindow prefix = window();
  EXPECT_FALSE(runWindow(prefix, 0.3, std::nullopt).at_rest);
  GyroBiasWindow whole = window();
  const GyroBiasEstimate e = runWindow(whole, 10.0, std::nullopt);
  ASSERT_TRUE(e.at_rest);
  EXPECT_FALSE(e.rest_prefix);
  EXPECT_NEAR(e.rest_s, 1.0, 0.002);
  // A whole still window keeps the white noise alone: σ_g / √T, 0.0115 °/s.
  EXPECT_NEAR(std::sqrt(e.covariance(0, 0)), 2e-4, 2e-6);
}

}  // namespace
}  // namespace evio::estimator

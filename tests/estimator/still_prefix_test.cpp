// The still prefix (backend/still_prefix.h) on synthetic 1 kHz IMU readings
// with exact truth: still with known biases and white noise at the stated
// densities, then a motion that starts at a known time. Where the prefix
// ends against that time, how often a body still throughout is cut short
// against the test's analytic false-alarm rate, the allowance against its
// formula, and the blind spot the header states (a steady turn from the
// first reading is taken for bias).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "evio/core/so3.h"
#include "evio/estimator/backend/still_prefix.h"

namespace evio::estimator {
namespace {

constexpr double kRateHz = 1000.0;
constexpr double kGravity = 9.81;

ImuNoiseDensities noise() {
  ImuNoiseDensities n;
  n.accelerometer_noise_density = 0.004316;  // the DAVIS240 reference densities
  n.gyroscope_noise_density = 2e-4;
  return n;
}

/// A body still until onset_s, then turning about x with angular
/// acceleration alpha (rad/s²) and accelerating along y with jerk (m/s³):
/// rate and force grow linearly from the onset.
struct Motion {
  double onset_s = 0.3;
  double alpha_radps2 = 0.0;
  double jerk_mps3 = 0.0;
  Vec3 steady_rate = Vec3::Zero();  ///< a turn at a constant rate from t = 0
};

ImuSamples readings(const Motion& m, double duration_s, std::mt19937_64& rng) {
  const ImuNoiseDensities n = noise();
  std::normal_distribution<double> unit(0.0, 1.0);
  const double sa = n.accelerometer_noise_density * std::sqrt(kRateHz);
  const double sg = n.gyroscope_noise_density * std::sqrt(kRateHz);
  const Vec3 b_g(0.03, -0.05, 0.02), b_a(0.1, -0.2, 0.05);
  ImuSamples out;
  const int count = static_cast<int>(std::lround(duration_s * kRateHz)) + 1;
  for (int k = 0; k < count; ++k) {
    const double t = k / kRateHz;
    const double moving = std::max(0.0, t - m.onset_s);
    ImuSample s;
    s.t_ns = secondsToNs(t);
    s.gyro_B = b_g + m.steady_rate + Vec3(m.alpha_radps2 * moving, 0.0, 0.0) + sg * Vec3(unit(rng), unit(rng), unit(rng));
    s.acc_B = Vec3(0.0, m.jerk_mps3 * moving, kGravity) + b_a + sa * Vec3(unit(rng), unit(rng), unit(rng));
    out.push_back(s);
  }
  return out;
}

double prefixEndS(const ImuSamples& s, const StillPrefix& p) { return nsToSeconds(s[p.readings - 1].t_ns); }

TEST(StillPrefix, EndsAtTheBlockWhereATurnStarts) {
  // Still for 0.3 s, then the rate grows at 10 °/s² (boxes_6dof's start).
  // Blocks of 50 readings: σ_b = 2e-4 √(1000/50) = 8.9e-4 rad/s, the
  // threshold 4 σ_b √(1 + 1/6) = 3.9e-3 rad/s; the first moving block's
  // mean is 10 °/s² × 25 ms = 4.4e-3 rad/s off, the next one's 1.3e-2.
  // So the prefix ends at the onset (0.3 s) or one block later, or one
  // block earlier on a false alarm (rate 3.8e-4 per block), never elsewhere;
  // its last reading is at 0.299, 0.349 or 0.249 s.
  int at_onset = 0;
  for (int seed = 0; seed < 50; ++seed) {
    std::mt19937_64 rng(1000 + seed);
    Motion m;
    m.alpha_radps2 = 10.0 * M_PI / 180.0;
    const ImuSamples s = readings(m, 1.0, rng);
    const auto p = stillPrefix(s, noise(), StillPrefixTest{});
    ASSERT_TRUE(p.has_value()) << "seed " << seed;
    const double end = prefixEndS(s, *p);
    EXPECT_GE(end, 0.249 - 1e-9) << "seed " << seed;
    EXPECT_LE(end, 0.349 + 1e-9) << "seed " << seed;
    at_onset += std::abs(end - 0.299) < 1e-6;
  }
  // The first moving block passes when its noise pulls it below the
  // threshold: P(N(4.3e-3, 9.7e-4) < 3.9e-3) ≈ 0.33. So about 67 % end at
  // the onset: 33.5 of 50 expected (σ 3.3), at least 20 (4σ below).
  EXPECT_GE(at_onset, 20);
}

TEST(StillPrefix, EndsWhereAnAccelerationStarts) {
  // Still for 0.4 s, then the force along y grows at 2 m/s³: σ_b of the
  // accelerometer 0.004316 √20 = 0.0193 m/s², threshold 4 σ_b √(1 + 1/8) =
  // 0.082 m/s²; the first moving block's mean is 0.049 m/s² off (it passes
  // in 96 % of draws), the second 0.149 (it never does): the prefix ends one
  // block after the onset, or at it, or a block earlier on a false alarm.
  for (int seed = 0; seed < 20; ++seed) {
    std::mt19937_64 rng(2000 + seed);
    Motion m;
    m.onset_s = 0.4;
    m.jerk_mps3 = 2.0;
    const ImuSamples s = readings(m, 1.0, rng);
    const auto p = stillPrefix(s, noise(), StillPrefixTest{});
    ASSERT_TRUE(p.has_value()) << "seed " << seed;
    const double end = prefixEndS(s, *p);
    EXPECT_GE(end, 0.349 - 1e-9) << "seed " << seed;
    EXPECT_LE(end, 0.449 + 1e-9) << "seed " << seed;
  }
}

TEST(StillPrefix, AStillBodyKeepsEveryBlockAtTheAnalyticFalseAlarmRate) {
  // 1 s still: 20 blocks of 50 readings (the 1001st reading is left over).
  // A block is cut on noise alone with probability 1 − (1 − 2Φ(−4))⁶ =
  // 3.8e-4 (six axes), so a window of 19 tested blocks is cut short with
  // probability 0.72 %: over 300 draws 2.2 expected, more than 9 has a
  // probability below 1e-3 (Poisson).
  int cut = 0;
  for (int seed = 0; seed < 300; ++seed) {
    std::mt19937_64 rng(3000 + seed);
    const ImuSamples s = readings(Motion{1e9}, 1.0, rng);
    const auto p = stillPrefix(s, noise(), StillPrefixTest{});
    ASSERT_TRUE(p.has_value());
    cut += p->readings != 1000;
  }
  EXPECT_LE(cut, 9);
}

TEST(StillPrefix, MotionFromTheStartLeavesNoPrefixButASteadyTurnPassesForBias) {
  std::mt19937_64 rng(4);
  Motion turning;
  turning.onset_s = 0.0;
  turning.alpha_radps2 = 10.0 * M_PI / 180.0;  // the second block is 8.7e-3 rad/s off: cut there
  EXPECT_FALSE(stillPrefix(readings(turning, 1.0, rng), noise(), StillPrefixTest{}).has_value());
  // The blind spot: a steady 2 °/s turn from the first reading has constant
  // block means, the whole second passes (its rate is taken for bias; the
  // rest update's χ² gate against the prior is the guard).
  Motion steady;
  steady.onset_s = 1e9;
  steady.steady_rate = Vec3(0.0, 0.0, 2.0 * M_PI / 180.0);
  const ImuSamples s = readings(steady, 1.0, rng);
  const auto p = stillPrefix(s, noise(), StillPrefixTest{});
  ASSERT_TRUE(p.has_value());
  EXPECT_EQ(p->readings, 1000u);
}

TEST(StillPrefix, TheAllowanceIsTheThresholdsUniformVarianceAndShortPrefixesAreRefused) {
  std::mt19937_64 rng(5);
  const ImuSamples s = readings(Motion{1e9}, 1.0, rng);
  StillPrefixTest test;
  const auto p = stillPrefix(s, noise(), test);
  ASSERT_TRUE(p.has_value());
  // (c σ_b)² / 3 with σ_b = σ √(f / n), f = 1000 Hz, n = 50.
  const double sg = 2e-4 * std::sqrt(1000.0 / 50.0), sa = 0.004316 * std::sqrt(1000.0 / 50.0);
  EXPECT_NEAR(p->gyro_allowance_variance, 16.0 * sg * sg / 3.0, 1e-15);
  EXPECT_NEAR(p->acc_allowance_variance, 16.0 * sa * sa / 3.0, 1e-12);
  // A body still for 0.12 s: two blocks (0.099 s to the last reading) are
  // below min_s = 0.1, so there is no prefix; with min_s 0.05 there is.
  std::mt19937_64 rng2(6);
  Motion early;
  early.onset_s = 0.1;
  early.alpha_radps2 = 1.0;  // 57 °/s²: the third block is far off
  const ImuSamples e = readings(early, 1.0, rng2);
  EXPECT_FALSE(stillPrefix(e, noise(), test).has_value());
  test.min_s = 0.05;
  const auto q = stillPrefix(e, noise(), test);
  ASSERT_TRUE(q.has_value());
  EXPECT_EQ(q->readings, 100u);
  // Too few readings for two blocks.
  EXPECT_FALSE(stillPrefix(ImuSamples(s.begin(), s.begin() + 60), noise(), StillPrefixTest{}).has_value());
}

/// Bearings of 30 static points 2–6 m in front of a camera turning at ω_C
/// (its own frame) from t = 0, seen at 0 and every 50 ms to `end_s`, each
/// with white noise σ per axis (then renormalised).
std::vector<BearingObservation> turningBearings(const Vec3& omega_C, double end_s, double sigma_rad,
                                                std::mt19937_64& rng) {
  std::normal_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> spread(-0.6, 0.6), depth(2.0, 6.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 30; ++i) points.push_back(depth(rng) * Vec3(spread(rng), spread(rng), 1.0));
  std::vector<BearingObservation> out;
  for (double t = 0.0; t <= end_s + 1e-9; t += 0.05) {
    const Mat3 R_0_C = so3::exp(omega_C * t);  // the camera at t in the camera at 0
    for (int i = 0; i < 30; ++i) {
      const Vec3 b = (R_0_C.transpose() * points[i]).normalized();
      const Vec3 noisy = (b + sigma_rad * Vec3(unit(rng), unit(rng), unit(rng))).normalized();
      out.push_back(BearingObservation{secondsToNs(t), i, noisy});
    }
  }
  return out;
}

TEST(ImageRotationRate, FindsTheTurnWithinItsCovarianceAndAStillCameraPassesTheGate) {
  // σ = 5e-4 rad (0.1 px at 200 px) per axis, 0.2 s. The estimate's NEES over
  // 400 draws of a 5 °/s turn against χ²₃: mean 3, 99 % bounds of the mean
  // [2.64, 3.38]. (The model is the first-order one: at 5 °/s over 0.2 s the
  // second-order term is 3e-4 of the motion, far below the noise.)
  const double sigma = 5e-4;
  const Vec3 omega(0.03, -0.05, 0.07);  // rad/s, |ω| = 5.1 °/s
  double nees = 0.0;
  for (int seed = 0; seed < 400; ++seed) {
    std::mt19937_64 rng(5000 + seed);
    const auto obs = turningBearings(omega, 0.2, sigma, rng);
    const auto rate = imageRotationRate(obs, 0, secondsToNs(0.2), sigma);
    ASSERT_TRUE(rate.has_value());
    EXPECT_EQ(rate->features, 30);
    const Vec3 d = rate->omega_C - omega;
    nees += d.dot(rate->covariance.inverse() * d);
  }
  nees /= 400.0;
  std::printf("image rotation rate: mean NEES %.3f over 400 draws\n", nees);
  EXPECT_GT(nees, 2.64);
  EXPECT_LT(nees, 3.38);
  // Still: χ²₃ under the gate (16.27) in all but a few of 400 draws (0.1 %
  // expected: at most 3); turning at 5 °/s: far over it in every draw.
  int over = 0;
  for (int seed = 0; seed < 400; ++seed) {
    std::mt19937_64 rng(6000 + seed);
    const auto still = imageRotationRate(turningBearings(Vec3::Zero(), 0.2, sigma, rng), 0, secondsToNs(0.2), sigma);
    ASSERT_TRUE(still.has_value());
    over += still->chi2() > 16.27;
  }
  EXPECT_LE(over, 3);
  std::mt19937_64 rng(7);
  const auto turning = imageRotationRate(turningBearings(omega, 0.2, sigma, rng), 0, secondsToNs(0.2), sigma);
  ASSERT_TRUE(turning.has_value());
  EXPECT_GT(turning->chi2(), 1000.0);
}

TEST(ImageRotationRate, TracksThatJumpAboutCountAgainstRestAndTooFewCannotTell) {
  // A still camera whose tracker jumps one feature by 20 px (0.1 rad at
  // 200 px): the stated noise does not grow with it, so the gate fails.
  std::mt19937_64 rng(8);
  const double sigma = 5e-4;
  auto obs = turningBearings(Vec3::Zero(), 0.2, sigma, rng);
  for (BearingObservation& o : obs)
    if (o.id == 3 && o.t_ns == secondsToNs(0.2)) o.bearing = (o.bearing + Vec3(0.1, 0.0, 0.0)).normalized();
  const auto rate = imageRotationRate(obs, 0, secondsToNs(0.2), sigma);
  ASSERT_TRUE(rate.has_value());
  EXPECT_GT(rate->chi2(), 16.27);
  // Only the features seen twice at least min_span_s apart count: four are
  // not enough to tell.
  std::vector<BearingObservation> few;
  for (const BearingObservation& o : obs)
    if (o.id < 4) few.push_back(o);
  EXPECT_FALSE(imageRotationRate(few, 0, secondsToNs(0.2), sigma).has_value());
  // The interval limits which observations count: up to 10 ms, one per feature.
  EXPECT_FALSE(imageRotationRate(obs, 0, secondsToNs(0.01), sigma).has_value());
}

}  // namespace
}  // namespace evio::estimator

// The IMU noise has the meaning estimators assume: long fixed-seed sequences
// reproduce the white-noise density (Allan deviation at τ = 1 s) and the bias
// random-walk density (growth of the bias variance), for gyro and accelerometer.

#include <gtest/gtest.h>

#include <cmath>

#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

/// Overlapping Allan deviation at τ = m Δt of a rate signal y sampled every Δt
/// (IEEE Std 952): with θ_k = Δt Σ_{i<k} y_i,
///   σ²(τ) = Σ_{k=0}^{N−2m} (θ_{k+2m} − 2θ_{k+m} + θ_k)² / (2 τ² (N − 2m + 1)).
/// For white noise of density σ_c: σ(τ) = σ_c / √τ; a random walk of density
/// σ_b adds σ_b² τ / 3 to σ²(τ).
double allanDeviation(const std::vector<double>& y, double dt, std::size_t m) {
  std::vector<double> theta(y.size() + 1, 0.0);
  for (std::size_t i = 0; i < y.size(); ++i) theta[i + 1] = theta[i] + y[i] * dt;
  const std::size_t n = theta.size();
  double sum = 0.0;
  for (std::size_t k = 0; k + 2 * m < n; ++k) {
    const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
    sum += d * d;
  }
  const double tau = static_cast<double>(m) * dt;
  return std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(n - 2 * m)));
}

/// Estimated random-walk density from independent increments of a logged
/// bias over windows of `window` samples: Var(b(t+T) − b(t)) = σ_b² T.
double walkDensity(const std::vector<double>& b, double dt, std::size_t window) {
  double sum = 0.0;
  std::size_t count = 0;
  for (std::size_t k = 0; k + window < b.size(); k += window) {
    const double d = b[k + window] - b[k];
    sum += d * d;
    ++count;
  }
  const double T = static_cast<double>(window) * dt;
  return std::sqrt(sum / static_cast<double>(count) / T);
}

TEST(ImuNoiseStatistics, AllanDeviationAndBiasWalkMatchTheDensities) {
  // One hour of hover at 200 Hz (720 001 samples). The error e = reading − ideal
  // is white noise + bias. σ_A(1 s) is estimated from ~3 600 s / 1 s
  // overlapping clusters (relative standard error ≈ 1 %), the walk from
  // 3 600 (T = 1 s) and 1 800 (T = 2 s) independent increments per axis
  // (≈ 2.4 % and 3.3 %): the 10 % bounds are several standard errors wide.
  const auto traj = makeTrajectory(test::trajectoryPresetPath("hover.yaml"), {"duration_s=3600"});
  ImuSimulator::Options o;
  o.update_rate_hz = 200.0;
  o.accelerometer_noise_density = 0.004316;
  o.accelerometer_random_walk = 0.0004316;
  o.gyroscope_noise_density = 0.0002;
  o.gyroscope_random_walk = 0.00002;
  ImuSimulator sim(*traj, o, 2024);
  std::array<std::vector<double>, 3> acc_err, gyro_err, acc_bias, gyro_bias;
  for (auto* v : {&acc_err, &gyro_err, &acc_bias, &gyro_bias})
    for (auto& axis : *v) axis.reserve(static_cast<std::size_t>(sim.sampleCount()));
  ImuMeasurement m;
  while (sim.next(m)) {
    const Vec3 ea = m.sample.acc_B - m.ideal.acc_B, eg = m.sample.gyro_B - m.ideal.gyro_B;
    for (int i = 0; i < 3; ++i) {
      acc_err[i].push_back(ea(i));
      gyro_err[i].push_back(eg(i));
      acc_bias[i].push_back(m.accel_bias(i));
      gyro_bias[i].push_back(m.gyro_bias(i));
    }
  }
  ASSERT_EQ(acc_err[0].size(), 720001u);
  const double dt = 1.0 / o.update_rate_hz;
  const auto expectedAllan = [](double white, double walk) {  // at τ = 1 s
    return std::sqrt(white * white + walk * walk / 3.0);
  };
  for (int i = 0; i < 3; ++i) {
    const double sa = allanDeviation(acc_err[i], dt, 200);
    const double sg = allanDeviation(gyro_err[i], dt, 200);
    const double ea = expectedAllan(o.accelerometer_noise_density, o.accelerometer_random_walk);
    const double eg = expectedAllan(o.gyroscope_noise_density, o.gyroscope_random_walk);
    EXPECT_NEAR(sa / ea, 1.0, 0.10) << "accelerometer axis " << i;
    EXPECT_NEAR(sg / eg, 1.0, 0.10) << "gyroscope axis " << i;
    std::printf("axis %d: Allan(1 s)/density accel %.4f gyro %.4f", i, sa / ea, sg / eg);
    for (const std::size_t window : {200u, 400u}) {
      const double wa = walkDensity(acc_bias[i], dt, window) / o.accelerometer_random_walk;
      const double wg = walkDensity(gyro_bias[i], dt, window) / o.gyroscope_random_walk;
      EXPECT_NEAR(wa, 1.0, 0.10) << "accelerometer walk axis " << i << " window " << window;
      EXPECT_NEAR(wg, 1.0, 0.10) << "gyroscope walk axis " << i << " window " << window;
      std::printf("; walk(T=%.0f s)/density accel %.4f gyro %.4f", window * dt, wa, wg);
    }
    std::printf("\n");
  }
  // The per-sample white noise is σ_c/√Δt: check the raw standard deviation too
  // (the bias is removed by differencing consecutive errors: Var(e_k − e_{k−1}) ≈ 2σ²).
  double s2 = 0.0;
  for (std::size_t k = 1; k < gyro_err[0].size(); ++k) {
    const double d = gyro_err[0][k] - gyro_err[0][k - 1];
    s2 += d * d;
  }
  const double sigma = std::sqrt(s2 / (2.0 * static_cast<double>(gyro_err[0].size() - 1)));
  EXPECT_NEAR(sigma / (o.gyroscope_noise_density / std::sqrt(dt)), 1.0, 0.01);
}

}  // namespace
}  // namespace evio

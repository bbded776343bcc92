// For every preset: the noiseless IMU at 1 kHz, integrated by 4th-order
// Runge–Kutta from the true initial state, reproduces the trajectory.

#include <gtest/gtest.h>

#include <numbers>
#include <yaml-cpp/yaml.h>

#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

struct NavState {
  Vec4 q;  // Hamilton quaternion of R_W_B as (x, y, z, w)
  Vec3 p;  // p_W_B
  Vec3 v;  // v_W
};

Quat toQuat(const Vec4& c) { return Quat(c(3), c(0), c(1), c(2)); }

/// Kinematics driven by the IMU: q̇ = ½ q ⊗ (ω_B, 0), ṗ = v, v̇ = R(q) a_B + g_W.
NavState derivative(const NavState& x, const Vec3& acc_B, const Vec3& gyro_B, const Vec3& g_W) {
  const Quat q = toQuat(x.q);
  const Quat omega(0.0, gyro_B.x(), gyro_B.y(), gyro_B.z());
  const Quat q_dot = q * omega;
  NavState d;
  d.q = 0.5 * q_dot.coeffs();
  d.p = x.v;
  // R(q) a with q not exactly unit inside a stage: use the normalised rotation.
  d.v = q.normalized() * acc_B + g_W;
  return d;
}

NavState axpy(const NavState& x, double h, const NavState& d) {
  return {x.q + h * d.q, x.p + h * d.p, x.v + h * d.v};
}

/// Cubic Lagrange value at the midpoint of samples k and k+1, from the four
/// samples around it (one-sided at the ends); error (3/128) h⁴ |f⁗|.
template <class Get>
Vec3 midpoint(const Get& f, std::size_t k, std::size_t n) {
  if (k == 0) return (5 * f(0) + 15 * f(1) - 5 * f(2) + f(3)) / 16.0;
  if (k + 2 >= n) return (f(k - 2) - 5 * f(k - 1) + 15 * f(k) + 5 * f(k + 1)) / 16.0;
  return (-f(k - 1) + 9 * f(k) + 9 * f(k + 1) - f(k + 2)) / 16.0;
}

class ImuIntegrationTest : public ::testing::TestWithParam<std::string> {};

TEST_P(ImuIntegrationTest, NoiselessImuAt1kHzReproducesTheTrajectory) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath(GetParam()));
  ImuSimulator::Options o;
  o.update_rate_hz = 1000.0;
  o.accelerometer_noise_density = o.accelerometer_random_walk = 0.0;
  o.gyroscope_noise_density = o.gyroscope_random_walk = 0.0;
  o.gravity_mps2 = YAML::Load(traj->configYaml())["gravity_mps2"].as<double>();
  ImuSimulator sim(*traj, o, 1);
  std::vector<ImuSample> samples;
  samples.reserve(static_cast<std::size_t>(sim.sampleCount()));
  ImuMeasurement m;
  while (sim.next(m)) samples.push_back(m.sample);
  ASSERT_GE(samples.size(), 60001u);

  const Vec3 g_W(0, 0, -o.gravity_mps2);
  const TrajectoryState s0 = traj->evaluate(samples[0].t_ns);
  NavState x{s0.T_W_B.quaternion().coeffs(), s0.T_W_B.translation(), s0.v_W};
  const auto acc = [&](std::size_t i) { return samples[i].acc_B; };
  const auto gyro = [&](std::size_t i) { return samples[i].gyro_B; };
  const std::size_t n = samples.size();
  double max_dp = 0.0, max_dq = 0.0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const double h = nsToSeconds(samples[k + 1].t_ns - samples[k].t_ns);
    const Vec3 a_mid = midpoint(acc, k, n), w_mid = midpoint(gyro, k, n);
    const NavState k1 = derivative(x, acc(k), gyro(k), g_W);
    const NavState k2 = derivative(axpy(x, 0.5 * h, k1), a_mid, w_mid, g_W);
    const NavState k3 = derivative(axpy(x, 0.5 * h, k2), a_mid, w_mid, g_W);
    const NavState k4 = derivative(axpy(x, h, k3), acc(k + 1), gyro(k + 1), g_W);
    x.q += h / 6.0 * (k1.q + 2.0 * k2.q + 2.0 * k3.q + k4.q);
    x.p += h / 6.0 * (k1.p + 2.0 * k2.p + 2.0 * k3.p + k4.p);
    x.v += h / 6.0 * (k1.v + 2.0 * k2.v + 2.0 * k3.v + k4.v);
    x.q.normalize();
    const TrajectoryState truth = traj->evaluate(samples[k + 1].t_ns);
    max_dp = std::max(max_dp, (x.p - truth.T_W_B.translation()).norm());
    max_dq = std::max(max_dq, angleBetween(toQuat(x.q), truth.T_W_B.quaternion()));
  }
  const TrajectoryState last = traj->evaluate(samples.back().t_ns);
  const double end_dp = (x.p - last.T_W_B.translation()).norm();
  const double end_dq_deg = angleBetween(toQuat(x.q), last.T_W_B.quaternion()) * 180.0 / std::numbers::pi;
  EXPECT_LT(end_dp, 1e-3);
  EXPECT_LT(end_dq_deg, 0.01);
  EXPECT_LT(max_dp, 1e-3);
  EXPECT_LT(max_dq * 180.0 / std::numbers::pi, 0.01);
  std::printf("[%s] after %.0f s: position error %.2e m, attitude error %.2e deg (max over run %.2e m, %.2e deg)\n",
              GetParam().c_str(), nsToSeconds(samples.back().t_ns - samples[0].t_ns), end_dp, end_dq_deg,
              max_dp, max_dq * 180.0 / std::numbers::pi);
}

INSTANTIATE_TEST_SUITE_P(AllPresets, ImuIntegrationTest, ::testing::ValuesIn(test::trajectoryPresetFiles()),
                         [](const auto& param_info) { return test::presetTestName(param_info.param); });

}  // namespace
}  // namespace evio

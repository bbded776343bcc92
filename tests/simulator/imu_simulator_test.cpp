#include "evio/simulator/imu_simulator.h"

#include <gtest/gtest.h>

#include "evio/core/io/config.h"
#include "evio/core/so3.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

ImuSimulator::Options noiseless() {
  ImuSimulator::Options o;
  o.accelerometer_noise_density = o.accelerometer_random_walk = 0.0;
  o.gyroscope_noise_density = o.gyroscope_random_walk = 0.0;
  return o;
}

std::vector<ImuMeasurement> run(const ContinuousTrajectory& traj, const ImuSimulator::Options& o,
                                std::uint64_t seed) {
  ImuSimulator sim(traj, o, seed);
  std::vector<ImuMeasurement> out;
  ImuMeasurement m;
  while (sim.next(m)) out.push_back(m);
  EXPECT_EQ(static_cast<std::int64_t>(out.size()), sim.sampleCount());
  return out;
}

std::unique_ptr<ContinuousTrajectory> preset(const std::string& name, std::vector<std::string> overrides = {}) {
  return makeTrajectory(test::trajectoryPresetPath(name), overrides);
}

TEST(ImuSimulator, IdealSpecificForceIsGravityReactionInTheBodyFrame) {
  // At rest and level: a_B = R_B_W (0 − g_W) = (0, 0, g).
  TrajectoryState rest;
  EXPECT_EQ(ImuSimulator::ideal(rest, 3.721).acc_B, Vec3(0, 0, 3.721));
  // Rolled by 90° about x: W's z is B's −y... a_B = R_B_W (0,0,g) = (0, g, 0).
  rest.T_W_B = Pose(so3::expQuat(Vec3(std::numbers::pi / 2, 0, 0)), Vec3::Zero());
  EXPECT_LT((ImuSimulator::ideal(rest, 9.81).acc_B - Vec3(0, 9.81, 0)).norm(), 1e-14);
  // Free fall reads zero.
  rest.a_W = Vec3(0, 0, -9.81);
  EXPECT_LT(ImuSimulator::ideal(rest, 9.81).acc_B.norm(), 1e-14);
}

TEST(ImuSimulator, SamplesOnAnExactGridOverTheWholeTrajectory) {
  const auto traj = preset("hover.yaml", {"duration_s=2"});
  ImuSimulator::Options o = noiseless();
  o.update_rate_hz = 200.0;
  const auto samples = run(*traj, o, 1);
  ASSERT_EQ(samples.size(), 401u);
  for (std::size_t k = 0; k < samples.size(); ++k) {
    ASSERT_EQ(samples[k].sample.t_ns, static_cast<TimeNs>(k) * 5'000'000);
    ASSERT_EQ(samples[k].truth.t_ns, samples[k].sample.t_ns);
  }
  o.update_rate_hz = 300.0;  // a period of 3 333 333.3 ns: rounded per sample, no drift
  const auto s300 = run(*traj, o, 1);
  ASSERT_EQ(s300.size(), 601u);
  EXPECT_EQ(s300[3].sample.t_ns, 10'000'000);
  EXPECT_EQ(s300.back().sample.t_ns, 2 * kNsPerSecond);
}

TEST(ImuSimulator, ScaleMisalignmentBiasAndSaturationFollowTheModel) {
  const auto traj = preset("six_dof.yaml");
  ImuSimulator::Options o = noiseless();
  o.accelerometer_initial_bias_mps2 = Vec3(0.1, -0.2, 0.3);
  o.gyroscope_initial_bias_radps = Vec3(-0.01, 0.02, 0.005);
  o.accelerometer_scale = Vec3(1.01, 0.99, 1.02);
  o.gyroscope_scale = Vec3(0.98, 1.03, 1.0);
  o.accelerometer_misalignment = so3::exp(Vec3(0.01, -0.02, 0.005));
  o.gyroscope_misalignment << 1, 0.01, 0, 0, 1, -0.02, 0, 0, 1;
  o.accelerometer_saturation_mps2 = 15.0;
  o.gyroscope_saturation_radps = 4.0;
  int saturated = 0;
  for (const auto& m : run(*traj, o, 1)) {
    const Vec3 a = (o.accelerometer_scale.asDiagonal() * (o.accelerometer_misalignment * m.ideal.acc_B) +
                    o.accelerometer_initial_bias_mps2)
                       .cwiseMax(-15.0)
                       .cwiseMin(15.0);
    const Vec3 w = (o.gyroscope_scale.asDiagonal() * (o.gyroscope_misalignment * m.ideal.gyro_B) +
                    o.gyroscope_initial_bias_radps)
                       .cwiseMax(-4.0)
                       .cwiseMin(4.0);
    ASSERT_LT((m.sample.acc_B - a).norm(), 1e-12);
    ASSERT_LT((m.sample.gyro_B - w).norm(), 1e-12);
    ASSERT_LE(m.sample.acc_B.cwiseAbs().maxCoeff(), 15.0);
    ASSERT_EQ(m.accel_bias, o.accelerometer_initial_bias_mps2);  // no random walk
    saturated += (m.sample.acc_B.cwiseAbs().maxCoeff() == 15.0) + (m.sample.gyro_B.cwiseAbs().maxCoeff() == 4.0);
  }
  EXPECT_GT(saturated, 100);  // the limits were actually reached
}

TEST(ImuSimulator, TimeshiftStampsTheMotionOfAnEarlierTrueTime) {
  const auto traj = preset("rotation_only.yaml", {"duration_s=3"});
  ImuSimulator::Options o = noiseless();
  o.timeshift_cam_imu_s = 0.0025;  // t_imu = t_cam + 2.5 ms
  const auto samples = run(*traj, o, 1);
  ASSERT_FALSE(samples.empty());
  EXPECT_EQ(samples.front().sample.t_ns, 2'500'000);
  for (const auto& m : samples) {
    ASSERT_EQ(m.truth.t_ns, m.sample.t_ns - 2'500'000);
    ASSERT_EQ(m.sample.gyro_B, traj->evaluate(m.sample.t_ns - 2'500'000).omega_B);
  }
  EXPECT_LE(samples.back().truth.t_ns, traj->endTime());
}

TEST(ImuSimulator, SameSeedSameSamplesAndOneStreamPerSource) {
  const auto traj = preset("circle.yaml", {"duration_s=5"});
  const ImuSimulator::Options o;
  const auto a = run(*traj, o, 42), b = run(*traj, o, 42), c = run(*traj, o, 43);
  ASSERT_EQ(a.size(), b.size());
  bool differs = false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(a[i].sample == b[i].sample);
    ASSERT_EQ(a[i].gyro_bias, b[i].gyro_bias);
    differs = differs || !(a[i].sample == c[i].sample);
  }
  EXPECT_TRUE(differs);
  // Changing the gyroscope's densities leaves every accelerometer draw alone.
  ImuSimulator::Options o2 = o;
  o2.gyroscope_noise_density *= 3.0;
  o2.gyroscope_random_walk *= 3.0;
  const auto d = run(*traj, o2, 42);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].sample.acc_B, d[i].sample.acc_B);
    ASSERT_EQ(a[i].accel_bias, d[i].accel_bias);
  }
  EXPECT_NE(a[10].sample.gyro_B, d[10].sample.gyro_B);
}

TEST(ImuSimulator, OptionsAreValidatedByName) {
  const auto bad = [](const std::string& yaml) -> std::string {
    try {
      ImuSimulator::Options o;
      config::fill(config::loadString(yaml, "imu.yaml"), "", o);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(bad("update_rate_hz: 0\n").find("update_rate_hz"), std::string::npos);
  EXPECT_NE(bad("gyroscope_noise_density: -1\n").find("gyroscope_noise_density"), std::string::npos);
  EXPECT_NE(bad("accelerometer_scale: [1, 0, 1]\n").find("accelerometer_scale"), std::string::npos);
  EXPECT_NE(bad("gyroscope_misalignment: [0, 0, 0, 0, 1, 0, 0, 0, 1]\n").find("gyroscope_misalignment"),
            std::string::npos);
  EXPECT_NE(bad("update_rate: 200\n").find("imu.yaml:1"), std::string::npos);  // Kalibr's name lacks _hz
  EXPECT_EQ(bad("accelerometer_saturation_mps2: .inf\nupdate_rate_hz: 500\n"), "");
}

}  // namespace
}  // namespace evio

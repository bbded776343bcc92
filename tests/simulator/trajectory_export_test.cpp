#include "evio/simulator/trajectory_export.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/so3.h"
#include "evio/trajectories/trajectory_factory.h"
#include "temp_dir.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

TEST(TrajectoryExport, WritesGroundTruthImuAndTruthThatReadBack) {
  test::TempDir dir;
  const std::string preset = test::trajectoryPresetPath("rotation_only.yaml");
  const auto summary = exportTrajectoryPreset(preset, dir.file("out"), {"duration_s=4", "imu.update_rate_hz=500"});
  EXPECT_EQ(summary.groundtruth_poses, 801);  // 200 Hz over [0, 4] s
  EXPECT_EQ(summary.imu_samples, 2001);       // 500 Hz
  ASSERT_EQ(summary.files.size(), 4u);
  for (const auto& f : summary.files) EXPECT_TRUE(std::filesystem::exists(f)) << f;

  const auto traj = makeTrajectory(preset, {"duration_s=4"});
  const auto gt = io::readTum(dir.file("out/groundtruth.txt"));
  ASSERT_EQ(gt.size(), 801u);
  for (std::size_t i = 0; i < gt.size(); i += 37) {
    ASSERT_EQ(gt[i].t_ns, static_cast<TimeNs>(i) * 5'000'000);
    const Pose truth = traj->evaluate(gt[i].t_ns).T_W_B;
    EXPECT_EQ(gt[i].pose.translation(), truth.translation());
    EXPECT_LT(angleBetween(gt[i].pose.quaternion(), truth.quaternion()), 1e-15);
  }

  // imu.txt is the simulator's output for the preset's seed and gravity (Earth).
  ImuSimulator::Options o;
  o.update_rate_hz = 500.0;
  o.gravity_mps2 = 9.81;
  ImuSimulator sim(*traj, o, 1);
  const auto imu = io::readImuText(dir.file("out/imu.txt"));
  const auto states = io::readImuStateText(dir.file("out/truth/imu_state.txt"));
  ASSERT_EQ(imu.size(), 2001u);
  ASSERT_EQ(states.size(), 2001u);
  ImuMeasurement m;
  for (std::size_t i = 0; i < imu.size(); ++i) {
    ASSERT_TRUE(sim.next(m));
    ASSERT_TRUE(imu[i] == m.sample) << i;
    ASSERT_EQ(states[i].t_ns, m.truth.t_ns);
    ASSERT_EQ(states[i].T_W_B.translation(), m.truth.T_W_B.translation());
    ASSERT_EQ(states[i].omega_B, m.truth.omega_B);
    ASSERT_EQ(states[i].a_W, m.truth.a_W);
    ASSERT_EQ(states[i].accel_bias, m.accel_bias);
    ASSERT_EQ(states[i].gyro_bias, m.gyro_bias);
  }

  // trajectory.yaml rebuilds the same trajectory and names the IMU used.
  const auto doc = config::loadFile(dir.file("out/trajectory.yaml"));
  const auto rebuilt = makeTrajectory(doc, "trajectory");
  EXPECT_EQ(rebuilt->configYaml(), traj->configYaml());
  ImuSimulator::Options written;
  config::fill(doc, "export.imu", written);
  EXPECT_TRUE(config::equal(written, o));
  EXPECT_EQ(doc.root["seed"].as<std::uint64_t>(), 1u);
}

TEST(TrajectoryExport, SameSeedSameBytesAndOtherSeedOtherNoise) {
  test::TempDir dir;
  const std::string preset = test::trajectoryPresetPath("hover.yaml");
  const std::vector<std::string> set = {"duration_s=3"};
  exportTrajectoryPreset(preset, dir.file("a"), set);
  exportTrajectoryPreset(preset, dir.file("b"), set);
  auto other = set;
  other.push_back("seed=2");
  exportTrajectoryPreset(preset, dir.file("c"), other);
  for (const char* f : {"groundtruth.txt", "imu.txt", "truth/imu_state.txt", "trajectory.yaml"}) {
    const std::string a = io::readFile(dir.file(std::string("a/") + f));
    EXPECT_EQ(a, io::readFile(dir.file(std::string("b/") + f))) << f;
    EXPECT_NE(a, io::readFile(dir.file(std::string("c/") + f))) << f;
    EXPECT_GT(a.size(), 100u);
  }
  // Re-exporting into an existing folder replaces the files with the same bytes.
  exportTrajectoryPreset(preset, dir.file("a"), set);
  EXPECT_EQ(io::readFile(dir.file("a/imu.txt")), io::readFile(dir.file("b/imu.txt")));
}

TEST(TrajectoryExport, CameraFrameGroundTruthAndExportOverrides) {
  test::TempDir dir;
  const auto traj = makeTrajectory(test::trajectoryPresetPath("circle.yaml"), {"duration_s=2"});
  TrajectoryExportOptions options;
  options.groundtruth_rate_hz = 50.0;
  options.imu.update_rate_hz = 200.0;
  const Pose T_B_C(so3::expQuat(Vec3(3.14159, 0, 0)), Vec3(0.05, 0, -0.02));
  const auto summary = exportTrajectory(*traj, options, 7, dir.file("cam"), T_B_C);
  EXPECT_EQ(summary.groundtruth_poses, 101);
  const auto gt = io::readTum(dir.file("cam/groundtruth.txt"));
  const Pose expected = traj->evaluate(gt[10].t_ns).T_W_B * T_B_C;
  EXPECT_LT((gt[10].pose.translation() - expected.translation()).norm(), 1e-15);

  const auto s = exportTrajectoryPreset(test::trajectoryPresetPath("circle.yaml"), dir.file("o"),
                                        {"duration_s=2", "export.groundtruth_rate_hz=10", "imu.update_rate_hz=100"});
  EXPECT_EQ(s.groundtruth_poses, 21);
  EXPECT_EQ(s.imu_samples, 201);
  const auto bad = [&](const std::string& set) -> std::string {
    try {
      exportTrajectoryPreset(test::trajectoryPresetPath("circle.yaml"), dir.file("x"), {"duration_s=1", set});
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(bad("imu.update_rate=100").find("--set imu.update_rate"), std::string::npos);
  EXPECT_NE(bad("export.groundtruth_rate_hz=0").find("groundtruth_rate_hz"), std::string::npos);
  EXPECT_NE(bad("radius_m=3").find("--set radius_m"), std::string::npos);
}

}  // namespace
}  // namespace evio

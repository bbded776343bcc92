#include "evio/core/io/sensors_yaml.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/so3.h"
#include "temp_dir.h"

namespace evio {
namespace {

SensorRig exampleRig() {
  RadTanCamera::Params radtan;
  radtan << 199.092366542, 198.82882047, 132.192071378, 110.712660011, -0.368436311798,
      0.150947243557, -0.000296130534385, -0.000759431726241, 0.0;
  EquidistantCamera::Params fisheye;
  fisheye << 300.1, 299.8, 254.9, 256.9, 0.0034823894022493434, 0.0007150348452162257,
      -0.0020532361418706202, 0.00020293673591811182;

  SensorRig rig;
  rig.cameras.push_back(CameraSensor{
      "dvs", CameraRole::kEvent, RadTanCamera(240, 180, radtan),
      Pose(so3::expQuat(Vec3(0.01, -0.02, 1.5707963)), Vec3(0.1 + 0.2, -0.003, 1e-5)),
      {{"contrast_threshold_pos", 0.2}, {"contrast_threshold_neg", 1.0 / 3.0},
       {"refractory_period_s", 1e-4}}});
  rig.cameras.push_back(CameraSensor{"frames", CameraRole::kFrame,
                                     EquidistantCamera(512, 512, fisheye),
                                     Pose(so3::expQuat(Vec3(2.0, 0.3, -0.7)), Vec3(0, 0.05, 0)),
                                     {{"exposure_s", 0.005}}});
  rig.cameras.push_back(CameraSensor{"ideal", CameraRole::kEvent,
                                     PinholeCamera(346, 260, PinholeCamera::Params(320, 320, 173, 130)),
                                     Pose::identity(),
                                     {}});
  rig.imu.accelerometer_noise_density = 0.0028;
  rig.imu.accelerometer_random_walk = 0.00086;
  rig.imu.gyroscope_noise_density = 0.00016;
  rig.imu.gyroscope_random_walk = 2.2e-05;
  rig.imu.update_rate = 1000.0;
  rig.gravity_m_s2 = 3.721;
  rig.time_offset_cam_imu_ns = -2'500'123;
  rig.range_finder = RangeFinderSensor{Pose(so3::expQuat(Vec3(3.1, 0, 0)), Vec3(0, 0, -0.2)), 0.1,
                                       100.0, 0.02};
  return rig;
}

// Rotations: Pose stores a quaternion, and a rotation matrix printed exactly
// reads back to a quaternion that can differ in the last bit, so rotations are
// compared to 4 · 2⁻⁵² (a few ulp); every other number must be bit-identical.
void expectPoseEqual(const Pose& a, const Pose& b) {
  EXPECT_EQ(a.translation(), b.translation());
  EXPECT_LT((a.rotation() - b.rotation()).cwiseAbs().maxCoeff(), 4.0 * 2.220446049250313e-16);
}

void expectRigEqual(const SensorRig& a, const SensorRig& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (std::size_t i = 0; i < a.cameras.size(); ++i) {
    EXPECT_EQ(a.cameras[i].name, b.cameras[i].name);
    EXPECT_EQ(a.cameras[i].role, b.cameras[i].role);
    EXPECT_EQ(a.cameras[i].camera, b.cameras[i].camera);
    EXPECT_EQ(a.cameras[i].parameters, b.cameras[i].parameters);
    expectPoseEqual(a.cameras[i].T_B_C, b.cameras[i].T_B_C);
  }
  EXPECT_EQ(a.imu.accelerometer_noise_density, b.imu.accelerometer_noise_density);
  EXPECT_EQ(a.imu.accelerometer_random_walk, b.imu.accelerometer_random_walk);
  EXPECT_EQ(a.imu.gyroscope_noise_density, b.imu.gyroscope_noise_density);
  EXPECT_EQ(a.imu.gyroscope_random_walk, b.imu.gyroscope_random_walk);
  EXPECT_EQ(a.imu.update_rate, b.imu.update_rate);
  EXPECT_EQ(a.gravity_m_s2, b.gravity_m_s2);
  EXPECT_EQ(a.time_offset_cam_imu_ns, b.time_offset_cam_imu_ns);
  ASSERT_EQ(a.range_finder.has_value(), b.range_finder.has_value());
  if (a.range_finder) {
    expectPoseEqual(a.range_finder->T_B_L, b.range_finder->T_B_L);
    EXPECT_EQ(a.range_finder->min_range_m, b.range_finder->min_range_m);
    EXPECT_EQ(a.range_finder->max_range_m, b.range_finder->max_range_m);
    EXPECT_EQ(a.range_finder->noise_sigma_m, b.range_finder->noise_sigma_m);
  }
}

TEST(SensorsYaml, RoundTripThroughFile) {
  test::TempDir dir;
  const std::string path = dir.file("sensors.yaml");
  const SensorRig rig = exampleRig();
  io::writeSensorsYaml(path, rig);
  const SensorRig back = io::readSensorsYaml(path);
  expectRigEqual(rig, back);
  // Numbers print in their shortest round-trip form.
  const std::string text = io::readFile(path);
  EXPECT_NE(text.find("intrinsics: [320, 320, 173, 130]"), std::string::npos) << text;
  EXPECT_NE(text.find("contrast_threshold_neg: 0.3333333333333333\n"), std::string::npos) << text;
  // The atomic writer leaves only the target behind.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
}

TEST(SensorsYaml, RoundTripWithoutOptionalParts) {
  SensorRig rig = exampleRig();
  rig.range_finder.reset();
  rig.time_offset_cam_imu_ns = 0;
  rig.cameras.erase(rig.cameras.begin() + 1, rig.cameras.end());
  const SensorRig back = io::parseSensorsYaml(io::formatSensorsYaml(rig), "t.yaml");
  expectRigEqual(rig, back);
}

const char* kMinimal = R"(cameras:
  - name: cam0
    role: event
    model: radtan
    resolution: [240, 180]
    intrinsics: [199.1, 198.8, 132.2, 110.7]
    distortion_coeffs: [-0.37, 0.15, 0, 0, 0]
    T_B_C:
      - [1, 0, 0, 0.1]
      - [0, 1, 0, 0]
      - [0, 0, 1, 0]
      - [0, 0, 0, 1]
imu:
  accelerometer_noise_density: 0.0028
  accelerometer_random_walk: 0.00086
  gyroscope_noise_density: 0.00016
  gyroscope_random_walk: 2.2e-05
  update_rate: 1000
gravity_m_s2: 3.721
)";

TEST(SensorsYaml, ReadsHandWrittenFile) {
  const SensorRig rig = io::parseSensorsYaml(kMinimal, "minimal.yaml");
  ASSERT_EQ(rig.cameras.size(), 1u);
  const CameraSensor& c = rig.cameras[0];
  EXPECT_EQ(c.name, "cam0");
  EXPECT_EQ(c.role, CameraRole::kEvent);
  EXPECT_EQ(c.camera.model(), "radtan");
  EXPECT_EQ(c.camera.width(), 240);
  EXPECT_EQ(c.camera.intrinsics(), Vec4(199.1, 198.8, 132.2, 110.7));
  EXPECT_EQ(c.T_B_C.translation(), Vec3(0.1, 0, 0));
  EXPECT_TRUE(c.T_B_C.rotation().isIdentity(0.0));
  EXPECT_TRUE(c.parameters.empty());
  EXPECT_EQ(rig.imu.update_rate, 1000.0);
  EXPECT_EQ(rig.time_offset_cam_imu_ns, 0);
  EXPECT_FALSE(rig.range_finder.has_value());
  EXPECT_EQ(rig.firstCamera(CameraRole::kEvent), &c);
  EXPECT_EQ(rig.firstCamera(CameraRole::kFrame), nullptr);
  EXPECT_EQ(rig.findCamera("cam0"), &c);

  // A flat list of 16 numbers (row-major) is the same transform.
  std::string flat = kMinimal;
  const std::string rows =
      "\n      - [1, 0, 0, 0.1]\n      - [0, 1, 0, 0]\n      - [0, 0, 1, 0]\n      - [0, 0, 0, 1]";
  flat.replace(flat.find(rows), rows.size(), " [1, 0, 0, 0.1, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]");
  EXPECT_EQ(io::parseSensorsYaml(flat, "flat.yaml").cameras[0].T_B_C.translation(), Vec3(0.1, 0, 0));
}

/// Replaces the first occurrence of `from` in kMinimal by `to`, parses, and
/// expects an evio::Error containing every string of `expected`.
void expectBad(const std::string& from, const std::string& to,
               std::initializer_list<std::string> expected) {
  std::string text = kMinimal;
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  try {
    io::parseSensorsYaml(text, "bad.yaml");
    ADD_FAILURE() << "expected an error for:\n" << text;
  } catch (const Error& e) {
    for (const auto& s : expected)
      EXPECT_NE(std::string(e.what()).find(s), std::string::npos) << e.what() << "\n(wanted " << s << ")";
  }
}

TEST(SensorsYaml, UnknownKeysAreRejectedWithFileAndLine) {
  expectBad("gravity_m_s2: 3.721", "gravity_m_s2: 3.721\ngravity: 9.81",
            {"bad.yaml:20", "gravity", "unknown key"});
  expectBad("  update_rate: 1000", "  update_rate: 1000\n  rate_hz: 5",
            {"bad.yaml:19", "imu.rate_hz", "unknown key"});
  expectBad("    role: event", "    role: event\n    rol: frame",
            {"bad.yaml:4", "cameras[0].rol", "unknown key"});
  expectBad("  update_rate: 1000", "  update_rate: 1000\n  update_rate: 200",
            {"bad.yaml:19", "imu.update_rate", "duplicate key"});
}

TEST(SensorsYaml, WrongTypesAndValuesNameFieldAndLine) {
  expectBad("update_rate: 1000", "update_rate: fast", {"bad.yaml:18", "imu.update_rate"});
  expectBad("resolution: [240, 180]", "resolution: [240.5, 180]",
            {"bad.yaml:5", "cameras[0].resolution[0]"});
  expectBad("resolution: [240, 180]", "resolution: 240", {"bad.yaml:5", "cameras[0].resolution"});
  expectBad("role: event", "role: lidar", {"bad.yaml:3", "cameras[0].role", "lidar"});
  expectBad("model: radtan", "model: fisheye", {"bad.yaml:4", "model", "fisheye"});
  expectBad("[199.1, 198.8, 132.2, 110.7]", "[-199.1, 198.8, 132.2, 110.7]",
            {"bad.yaml:6", "intrinsics.fx"});
  expectBad("[199.1, 198.8, 132.2, 110.7]", "[199.1, 198.8, 132.2]",
            {"bad.yaml:6", "cameras[0].intrinsics", "expected 4 numbers"});
  expectBad("[-0.37, 0.15, 0, 0, 0]", "[-0.37, 0.15, 0, 0]",
            {"bad.yaml:7", "distortion", "5 coefficients"});
  expectBad("[-0.37, 0.15, 0, 0, 0]", "[-0.37, .nan, 0, 0, 0]",
            {"bad.yaml:7", "distortion_coeffs[1]"});
  expectBad("gravity_m_s2: 3.721", "gravity_m_s2: .inf", {"bad.yaml:19", "gravity_m_s2", "finite"});
  expectBad("gravity_m_s2: 3.721", "gravity_m_s2: 0", {"bad.yaml:19", "gravity_m_s2", "> 0"});
  expectBad("gravity_m_s2: 3.721\n", "", {"bad.yaml:1", "gravity_m_s2", "missing required key"});
  const std::string no_cameras = "cameras: []\n" + std::string(kMinimal).substr(std::string(kMinimal).find("imu:"));
  try {
    io::parseSensorsYaml(no_cameras, "bad.yaml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("bad.yaml:1: cameras: expected a non-empty list"),
              std::string::npos) << e.what();
  }
}

TEST(SensorsYaml, AbsurdImuRateIsRejected) {  // issue 19: every rate has an upper bound
  expectBad("update_rate: 1000", "update_rate: 1e12", {"bad.yaml", "imu.update_rate", "100000"});
  const std::string ok = [] {
    std::string t = kMinimal;
    t.replace(t.find("update_rate: 1000"), 17, "update_rate: 1e5");
    return t;
  }();
  EXPECT_NO_THROW(io::parseSensorsYaml(ok, "ok.yaml"));
}

TEST(SensorsYaml, NegativeNoiseDensityIsRejected) {
  expectBad("gyroscope_noise_density: 0.00016", "gyroscope_noise_density: -0.00016",
            {"bad.yaml:16", "imu.gyroscope_noise_density", ">= 0"});
  expectBad("accelerometer_random_walk: 0.00086", "accelerometer_random_walk: -1e-3",
            {"bad.yaml:15", "imu.accelerometer_random_walk", ">= 0"});
}

TEST(SensorsYaml, NonRigidTransformIsRejected) {
  // Scaled rotation block.
  expectBad("- [1, 0, 0, 0.1]", "- [1.001, 0, 0, 0.1]",
            {"bad.yaml:9", "cameras[0].T_B_C", "orthonormal"});
  // Off by 1e-7 (within the 1e-6 tolerance) is accepted.
  std::string ok = kMinimal;
  ok.replace(ok.find("- [1, 0, 0, 0.1]"), 16, "- [1.0000001, 0, 0, 0.1]");
  EXPECT_NO_THROW(io::parseSensorsYaml(ok, "ok.yaml"));
  // A reflection.
  expectBad("- [1, 0, 0, 0.1]", "- [-1, 0, 0, 0.1]", {"bad.yaml:9", "reflection"});
  // Last row not 0 0 0 1.
  expectBad("- [0, 0, 0, 1]", "- [0, 0, 0.5, 1]", {"bad.yaml:9", "last row"});
  // Wrong shape.
  expectBad("      - [0, 0, 0, 1]\n", "", {"bad.yaml:9", "4x4"});
  expectBad("- [0, 0, 0, 1]", "- [0, 0, 1]", {"bad.yaml:12", "cameras[0].T_B_C[3]", "4x4"});
}

TEST(SensorsYaml, RangeFinderAndCameraNamesAreChecked) {
  expectBad("gravity_m_s2: 3.721",
            "gravity_m_s2: 3.721\nrange_finder:\n  T_B_L: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n"
            "  min_range_m: 5\n  max_range_m: 2\n  noise_sigma_m: 0.01",
            {"bad.yaml:23", "range_finder.max_range_m", "min_range_m"});
  expectBad("gravity_m_s2: 3.721",
            "gravity_m_s2: 3.721\nrange_finder:\n  T_B_L: [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n"
            "  min_range_m: 0.1\n  max_range_m: 2\n  noise_sigma_m: -0.01",
            {"bad.yaml:24", "range_finder.noise_sigma_m"});
  // Two cameras with the same name.
  std::string text = kMinimal;
  const auto imu_at = text.find("imu:");
  const std::string camera_block = text.substr(text.find("  - name"), imu_at - text.find("  - name"));
  text.insert(imu_at, camera_block);
  try {
    io::parseSensorsYaml(text, "dup.yaml");
    ADD_FAILURE();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("dup.yaml:13"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("duplicate camera name"), std::string::npos) << e.what();
  }
}

TEST(SensorsYaml, MissingFileAndSyntaxError) {
  try {
    io::readSensorsYaml("/nonexistent/sensors.yaml");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/sensors.yaml"), std::string::npos);
  }
  EXPECT_THROW(io::parseSensorsYaml("cameras: [\n", "x.yaml"), Error);
  EXPECT_THROW(io::parseSensorsYaml("", "x.yaml"), Error);
}

TEST(SensorsYaml, WriterRejectsInvalidRig) {
  SensorRig rig = exampleRig();
  rig.imu.gyroscope_random_walk = -1.0;
  EXPECT_THROW(io::formatSensorsYaml(rig), Error);
  rig = exampleRig();
  rig.cameras[1].name = rig.cameras[0].name;
  EXPECT_THROW(io::formatSensorsYaml(rig), Error);
  test::TempDir dir;
  EXPECT_THROW(io::writeSensorsYaml(dir.file("sensors.yaml"), rig), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.file("sensors.yaml")));
}

}  // namespace
}  // namespace evio

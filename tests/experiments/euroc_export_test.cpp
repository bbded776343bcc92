#include "evio/experiments/euroc_export.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <opencv2/core/persistence.hpp>

#include <filesystem>
#include <opencv2/core.hpp>

#include "evio/core/camera/equidistant_camera.h"
#include "evio/core/camera/radtan_camera.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tum.h"
#include "evio/core/so3.h"
#include "evio/experiments/campaign_results.h"
#include "support/test_trajectories.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

namespace fs = std::filesystem;

/// A small sequence: an event camera (radtan, with k3) and a separate
/// fisheye frame camera, 5 frames, 20 IMU samples, 100 ground-truth poses.
struct TestSequence {
  SensorRig rig;
  Trajectory groundtruth;  // T_W_E
  ImuSamples imu;
  std::vector<TimeNs> frame_times;

  explicit TestSequence(const std::string& folder) {
    RadTanCamera::Params radtan;
    radtan << 199.1, 198.8, 132.2, 110.7, -0.37, 0.15, -0.0003, -0.0008, 0.01;
    EquidistantCamera::Params fisheye;
    fisheye << 300.1, 299.8, 254.9, 256.9, 0.0035, 0.0007, -0.002, 0.0002;
    rig.cameras.push_back(CameraSensor{"dvs", CameraRole::kEvent, RadTanCamera(240, 180, radtan),
                                       Pose(so3::expQuat(Vec3(0.01, -0.02, 1.5707963)), Vec3(0.3, -0.003, 1e-5)),
                                       {}});
    rig.cameras.push_back(CameraSensor{"frames", CameraRole::kFrame, EquidistantCamera(512, 512, fisheye),
                                       Pose(so3::expQuat(Vec3(2.0, 0.3, -0.7)), Vec3(0, 0.05, 0)),
                                       {}});
    rig.imu = {0.0028, 0.00086, 0.00016, 2.2e-05, 200.0};
    rig.gravity_m_s2 = 3.721;
    rig.time_offset_cam_imu_ns = -2'500'000;
    io::writeSensorsYaml(folder + "/sensors.yaml", rig);
    groundtruth = test::wavyTrajectory(0.99, 0.01);
    io::writeTum(folder + "/groundtruth.txt", groundtruth);
    for (int i = 0; i < 20; ++i)
      imu.push_back({TimeNs{5'000'000} * i + 7, Vec3(0.1 * i, -0.2, 3.7 + i), Vec3(0.01, 0.02 * i, -0.03)});
    io::writeImuText(folder + "/imu.txt", imu);
    io::ImageFolderWriter frames(folder);
    for (int i = 0; i < 5; ++i) {
      cv::Mat img(8, 10, CV_8UC1, cv::Scalar(20 * i));
      frame_times.push_back(TimeNs{200'000'000} * i + 123);
      frames.append(frame_times.back(), img);
    }
    frames.close();
  }
};

/// Data rows of a EuRoC csv (the '#' header dropped) as numbers.
std::vector<std::vector<double>> csvNumbers(const std::string& path, std::string* header) {
  const auto rows = parseCsv(io::readFile(path));
  std::vector<std::vector<double>> out;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    if (r == 0) {
      *header = rows[0][0];
      continue;
    }
    std::vector<double> v;
    for (const auto& f : rows[r]) v.push_back(std::stod(f));
    out.push_back(v);
  }
  return out;
}

Mat4 yamlMatrix(const YAML::Node& rows) {
  Mat4 T;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) T(r, c) = rows[r][c].as<double>();
  return T;
}

TEST(EurocExport, WritesTheAslLayoutWithKalibrCalibration) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq);
  const TestSequence s(seq);
  const std::string out = dir.file("euroc");
  const EurocExportSummary summary = exportEuroc(seq, out);
  EXPECT_EQ(summary.frames, 5u);
  EXPECT_EQ(summary.imu_samples, 20u);
  EXPECT_EQ(summary.groundtruth_poses, s.groundtruth.size());
  EXPECT_FALSE(summary.groundtruth_from_imu_state);
  ASSERT_EQ(summary.warnings.size(), 2u);  // ground truth from groundtruth.txt, Mars gravity (fisheye: no k3 warning)

  // cam0: ns stamps, files renamed to <t_ns>.png with the same bytes.
  const auto cam_rows = parseCsv(io::readFile(out + "/mav0/cam0/data.csv"));
  ASSERT_EQ(cam_rows.size(), 6u);
  EXPECT_EQ(cam_rows[0][0], "#timestamp [ns]");
  const auto list = io::readImageList(seq);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(cam_rows[i + 1][0], std::to_string(s.frame_times[i]));
    EXPECT_EQ(cam_rows[i + 1][1], std::to_string(s.frame_times[i]) + ".png");
    EXPECT_EQ(io::readFile(out + "/mav0/cam0/data/" + cam_rows[i + 1][1]), io::readFile(seq + "/" + list[i].relative_path));
  }

  // imu0: gyroscope before accelerometer, values exact.
  std::string header;
  const auto imu = csvNumbers(out + "/mav0/imu0/data.csv", &header);
  EXPECT_EQ(header, "#timestamp [ns]");
  ASSERT_EQ(imu.size(), s.imu.size());
  for (std::size_t i = 0; i < imu.size(); ++i) {
    EXPECT_EQ(static_cast<TimeNs>(imu[i][0]), s.imu[i].t_ns);
    EXPECT_EQ(Vec3(imu[i][1], imu[i][2], imu[i][3]), s.imu[i].gyro_B);
    EXPECT_EQ(Vec3(imu[i][4], imu[i][5], imu[i][6]), s.imu[i].acc_B);
  }

  // Ground truth of the body: quaternion w first, T_W_B · T_B_E = T_W_E.
  const auto gt = csvNumbers(out + "/mav0/state_groundtruth_estimate0/data.csv", &header);
  ASSERT_EQ(gt.size(), s.groundtruth.size());
  const Pose& T_B_E = s.rig.cameras[0].T_B_C;
  for (std::size_t i = 0; i < gt.size(); ++i) {
    ASSERT_EQ(gt[i].size(), 17u);
    EXPECT_EQ(static_cast<TimeNs>(gt[i][0]), s.groundtruth[i].t_ns);
    const Pose T_W_B(Quat(gt[i][4], gt[i][5], gt[i][6], gt[i][7]), Vec3(gt[i][1], gt[i][2], gt[i][3]));
    const Pose T_W_E = T_W_B * T_B_E;
    EXPECT_LT((T_W_E.translation() - s.groundtruth[i].pose.translation()).norm(), 1e-12);
    EXPECT_LT(angleBetween(T_W_E.quaternion(), s.groundtruth[i].pose.quaternion()), 1e-12);
    if (i > 0 && i + 1 < gt.size()) {  // central difference of the body positions
      const Vec3 v(gt[i][8], gt[i][9], gt[i][10]);
      const Vec3 expected = (Vec3(gt[i + 1][1], gt[i + 1][2], gt[i + 1][3]) - Vec3(gt[i - 1][1], gt[i - 1][2], gt[i - 1][3])) / 0.02;
      EXPECT_LT((v - expected).norm(), 1e-9);
    }
  }

  // Kalibr chain: cam0 is the frame camera; T_cam_imu maps IMU points into it.
  const YAML::Node chain = YAML::LoadFile(out + "/camchain.yaml")["cam0"];
  const Mat4 T_cam_imu = yamlMatrix(chain["T_cam_imu"]);
  EXPECT_LT((T_cam_imu * s.rig.cameras[1].T_B_C.matrix() - Mat4::Identity()).norm(), 1e-12);
  EXPECT_EQ(chain["camera_model"].as<std::string>(), "pinhole");
  EXPECT_EQ(chain["distortion_model"].as<std::string>(), "equidistant");
  EXPECT_EQ(chain["distortion_coeffs"][0].as<double>(), 0.0035);
  EXPECT_EQ(chain["intrinsics"][0].as<double>(), 300.1);
  EXPECT_EQ(chain["resolution"][0].as<int>(), 512);
  EXPECT_EQ(chain["timeshift_cam_imu"].as<double>(), -0.0025);
  const YAML::Node imu_yaml = YAML::LoadFile(out + "/imu.yaml")["imu0"];
  EXPECT_EQ(imu_yaml["gyroscope_noise_density"].as<double>(), 0.00016);
  EXPECT_EQ(imu_yaml["accelerometer_random_walk"].as<double>(), 0.00086);
  EXPECT_EQ(imu_yaml["update_rate"].as<double>(), 200.0);
  const YAML::Node sensor = YAML::LoadFile(out + "/mav0/cam0/sensor.yaml");
  EXPECT_EQ(sensor["T_BS"]["data"][3].as<double>(), s.rig.cameras[1].T_B_C.translation().x());
  EXPECT_EQ(YAML::LoadFile(out + "/evio_export.yaml")["gravity_m_s2"].as<double>(), 3.721);
}

TEST(EurocExport, UsesTheTrueImuStateAndWarnsAboutADroppedK3) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq + "/truth");
  const TestSequence s(seq);
  std::vector<io::ImuTruthState> states(3);
  for (int i = 0; i < 3; ++i) {
    states[i].t_ns = TimeNs{1'000'000} * i;
    states[i].T_W_B = Pose(so3::expQuat(Vec3(0.1 * i, 0.2, 0.3)), Vec3(i, 2, 3));
    states[i].v_W = Vec3(1, 2, 3 + i);
    states[i].gyro_bias = Vec3(0.001, 0.002, 0.003);
    states[i].accel_bias = Vec3(0.01, 0.02, 0.03 * i);
  }
  io::writeImuStateText(seq + "/truth/imu_state.txt", states);
  const auto summary = exportEuroc(seq, dir.file("euroc"), {"dvs"});  // the radtan event camera as cam0
  EXPECT_TRUE(summary.groundtruth_from_imu_state);
  ASSERT_EQ(summary.warnings.size(), 2u);  // the dropped k3, and Mars gravity no peer assumes
  EXPECT_NE(summary.warnings[0].find("k3"), std::string::npos);
  EXPECT_NE(summary.warnings[1].find("gravity is 3.721"), std::string::npos);
  std::string header;
  const auto gt = csvNumbers(dir.file("euroc") + "/mav0/state_groundtruth_estimate0/data.csv", &header);
  ASSERT_EQ(gt.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    const Quat& q = states[i].T_W_B.quaternion();
    const std::vector<double> expected = {static_cast<double>(states[i].t_ns), double(i), 2, 3, q.w(), q.x(), q.y(),
                                          q.z(), 1, 2, 3.0 + i, 0.001, 0.002, 0.003, 0.01, 0.02, 0.03 * i};
    EXPECT_EQ(gt[static_cast<std::size_t>(i)], expected);
  }
  const YAML::Node chain = YAML::LoadFile(dir.file("euroc") + "/camchain.yaml")["cam0"];
  EXPECT_EQ(chain["distortion_model"].as<std::string>(), "radtan");
  EXPECT_EQ(chain["distortion_coeffs"].size(), 4u);
  EXPECT_EQ(chain["resolution"][0].as<int>(), 240);
  EXPECT_THROW(exportEuroc(seq, dir.file("x"), {"nope"}), Error);
  // A frames-only real recording (no sensors.yaml, no IMU): one error naming both.
  fs::remove(seq + "/imu.txt");
  fs::remove(seq + "/sensors.yaml");
  try {
    exportEuroc(seq, dir.file("y"));
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("missing: sensors.yaml, imu.txt"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.file("y")));
}

/// A matrix given as rows of flow sequences, read as OpenVINS does through cv::FileStorage.
Eigen::MatrixXd fileStorageRows(const cv::FileNode& node) {
  std::vector<std::vector<double>> rows;
  for (const auto& r : node) {
    rows.emplace_back();
    for (const auto& v : r) rows.back().push_back(static_cast<double>(v));
  }
  Eigen::MatrixXd M(rows.size(), rows.empty() ? 0 : rows[0].size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < rows[i].size(); ++j) M(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = rows[i][j];
  return M;
}

TEST(EurocExport, EveryYamlFileIsReadByOpenCvsFileStorageAsPeersReadIt) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  fs::create_directories(seq);
  const TestSequence s(seq);
  const auto summary = exportEuroc(seq, dir.file("euroc"));
  const std::string out = dir.file("euroc");
  for (const char* f : {"camchain.yaml", "imu.yaml", "estimator_config.yaml", "evio_export.yaml", "mav0/body.yaml",
                        "mav0/cam0/sensor.yaml", "mav0/imu0/sensor.yaml",
                        "mav0/state_groundtruth_estimate0/sensor.yaml"}) {
    SCOPED_TRACE(f);
    EXPECT_EQ(io::readFile(out + "/" + f).rfind("%YAML:1.0\n", 0), 0u);
    cv::FileStorage file(out + "/" + f, cv::FileStorage::READ);
    ASSERT_TRUE(file.isOpened());
    EXPECT_FALSE(file.root().empty());
  }
  // imu.yaml: what OpenVINS' kalibr IMU loader requires, with the sequence's values.
  cv::FileStorage imu(out + "/imu.yaml", cv::FileStorage::READ);
  const cv::FileNode imu0 = imu["imu0"];
  EXPECT_EQ(static_cast<double>(imu0["gyroscope_noise_density"]), 0.00016);
  EXPECT_EQ(static_cast<double>(imu0["accelerometer_noise_density"]), 0.0028);
  EXPECT_EQ(static_cast<double>(imu0["update_rate"]), 200.0);
  for (const char* m : {"Tw", "R_IMUtoGYRO", "Ta", "R_IMUtoACC"}) {
    SCOPED_TRACE(m);
    const Eigen::MatrixXd M = fileStorageRows(imu0[m]);
    ASSERT_EQ(M.rows(), 3);
    EXPECT_EQ(M, Eigen::MatrixXd(Mat3::Identity()));
  }
  EXPECT_EQ(fileStorageRows(imu0["Tg"]), Eigen::MatrixXd(Mat3::Zero()));
  // camchain.yaml: T_cam_imu maps IMU points into the frame camera.
  cv::FileStorage chain(out + "/camchain.yaml", cv::FileStorage::READ);
  const Eigen::MatrixXd T_cam_imu = fileStorageRows(chain["cam0"]["T_cam_imu"]);
  ASSERT_EQ(T_cam_imu.rows(), 4);
  EXPECT_LT((T_cam_imu * s.rig.cameras[1].T_B_C.matrix() - Mat4::Identity()).norm(), 1e-12);
  EXPECT_EQ(static_cast<double>(chain["cam0"]["intrinsics"][0]), 300.1);
  EXPECT_EQ(static_cast<std::string>(chain["cam0"]["distortion_model"]), "equidistant");
  // Gravity where OpenVINS reads it, and loudly everywhere else.
  cv::FileStorage config(out + "/estimator_config.yaml", cv::FileStorage::READ);
  EXPECT_EQ(static_cast<double>(config["gravity_mag"]), 3.721);
  EXPECT_EQ(static_cast<std::string>(config["relative_config_imu"]), "imu.yaml");
  EXPECT_EQ(static_cast<std::string>(config["relative_config_imucam"]), "camchain.yaml");
  ASSERT_FALSE(summary.warnings.empty());
  EXPECT_NE(summary.warnings.back().find("gravity is 3.721"), std::string::npos);
  // EuRoC sensor blocks: T_BS as {cols, rows, data}.
  cv::FileStorage cam(out + "/mav0/cam0/sensor.yaml", cv::FileStorage::READ);
  EXPECT_EQ(static_cast<int>(cam["T_BS"]["rows"]), 4);
  EXPECT_EQ(static_cast<double>(cam["T_BS"]["data"][3]), s.rig.cameras[1].T_B_C.translation().x());
  cv::FileStorage gt(out + "/mav0/state_groundtruth_estimate0/sensor.yaml", cv::FileStorage::READ);
  EXPECT_EQ(static_cast<std::string>(gt["sensor_type"]), "visual-inertial");
}

}  // namespace
}  // namespace evio::experiments

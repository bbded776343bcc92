#include "evio/experiments/euroc_export.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/text_scanner.h"
#include "evio/core/io/tum.h"

namespace evio::experiments {

namespace {

namespace fs = std::filesystem;

/// Shortest round-trip text, never "-0", and with a '.' in the mantissa of
/// exponent forms ("3.0e-04"): YAML 1.1 readers (PyYAML, hence Kalibr) take
/// "3e-04" for a string.
std::string num(double v) {
  std::string s;
  io::appendDouble(s, v == 0.0 ? 0.0 : v);
  const std::size_t e = s.find_first_of("eE");
  if (e != std::string::npos && s.find('.') == std::string::npos) s.insert(e, ".0");
  return s;
}

/// Appends the CSV row "t_ns,v0,v1,…".
void row(std::string& out, TimeNs t_ns, std::initializer_list<double> values) {
  io::appendInt(out, t_ns);
  for (double v : values) {
    out += ',';
    io::appendDouble(out, v);
  }
  out += '\n';
}

/// A buffered, atomically committed CSV file.
class CsvFile {
 public:
  CsvFile(const fs::path& path, const std::string& header) : file_(path.string()) { buffer_ = header + "\n"; }
  std::string& buffer() { return buffer_; }
  void flushIfLarge() {
    if (buffer_.size() > (1u << 20)) flush();
  }
  void commit() {
    flush();
    file_.commit();
  }

 private:
  void flush() {
    file_.write(buffer_);
    buffer_.clear();
  }
  io::AtomicFile file_;
  std::string buffer_;
};

void emitMatrixRows(YAML::Emitter& out, const Mat4& T) {
  out << YAML::BeginSeq;
  for (int r = 0; r < 4; ++r) {
    out << YAML::Flow << YAML::BeginSeq;
    for (int c = 0; c < 4; ++c) out << num(T(r, c));
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq;
}

void emitFlow(YAML::Emitter& out, const std::vector<double>& v) {
  out << YAML::Flow << YAML::BeginSeq;
  for (double x : v) out << num(x);
  out << YAML::EndSeq;
}

/// A 3×3 matrix as rows of flow sequences (OpenVINS' Tw, Ta, Tg, R_IMUto*).
void emitMatrixRows3(YAML::Emitter& out, const Mat3& M) {
  out << YAML::BeginSeq;
  for (int r = 0; r < 3; ++r) {
    out << YAML::Flow << YAML::BeginSeq;
    for (int c = 0; c < 3; ++c) out << num(M(r, c));
    out << YAML::EndSeq;
  }
  out << YAML::EndSeq;
}

/// Writes a YAML file as the EuRoC layout and OpenCV's cv::FileStorage (used
/// by OpenVINS, VINS and most EuRoC readers) want it: "%YAML:1.0" first.
void writeYaml(const fs::path& path, const YAML::Emitter& e) {
  io::writeFileAtomic(path.string(), std::string("%YAML:1.0\n---\n") + e.c_str() + "\n");
}

/// Earth's standard gravity, the value every EuRoC peer assumes unless told.
constexpr double kPeerDefaultGravity = 9.81;

/// EuRoC's 4×4 matrix block {cols, rows, data}.
void emitEurocMatrix(YAML::Emitter& out, const Mat4& T) {
  out << YAML::BeginMap << YAML::Key << "cols" << YAML::Value << 4 << YAML::Key << "rows" << YAML::Value << 4;
  out << YAML::Key << "data" << YAML::Value << YAML::Flow << YAML::BeginSeq;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out << num(T(r, c));
  out << YAML::EndSeq << YAML::EndMap;
}

}  // namespace

EurocExportSummary exportEuroc(const std::string& sequence, const std::string& folder,
                               const EurocExportOptions& options) {
  EurocExportSummary summary;
  const fs::path seq(sequence);
  // A EuRoC sequence is a visual-inertial one: name everything that is missing at once.
  std::string missing;
  for (const char* needed : {"sensors.yaml", "images.txt", "imu.txt"})
    if (!fs::is_regular_file(seq / needed)) missing += std::string(missing.empty() ? "" : ", ") + needed;
  if (!missing.empty())
    throw Error(sequence + ": the EuRoC export needs the camera and IMU calibration (sensors.yaml), frames "
                           "(images.txt) and IMU (imu.txt); missing: " + missing);
  const SensorRig rig = io::readSensorsYaml((seq / "sensors.yaml").string());
  const CameraSensor* cam = options.camera.empty() ? rig.firstCamera(CameraRole::kFrame) : rig.findCamera(options.camera);
  if (!cam && options.camera.empty()) cam = &rig.cameras.front();
  if (!cam) throw Error((seq / "sensors.yaml").string() + ": no camera named '" + options.camera + "'");
  const CameraSensor* event_cam = rig.firstCamera(CameraRole::kEvent);
  if (!event_cam) event_cam = &rig.cameras.front();

  const fs::path out(folder), mav = out / "mav0";
  fs::create_directories(mav / "cam0" / "data");
  fs::create_directories(mav / "imu0");
  fs::create_directories(mav / "state_groundtruth_estimate0");

  // cam0: frames renamed to their nanosecond stamps.
  const auto frames = io::readImageList(sequence);
  if (frames.empty()) throw Error((seq / "images.txt").string() + ": no frames to export");
  CsvFile cam_csv(mav / "cam0" / "data.csv", "#timestamp [ns],filename");
  for (const auto& f : frames) {
    const std::string name = std::to_string(f.t_ns) + ".png";
    fs::copy_file(seq / f.relative_path, mav / "cam0" / "data" / name, fs::copy_options::overwrite_existing);
    io::appendInt(cam_csv.buffer(), f.t_ns);
    cam_csv.buffer() += "," + name + "\n";
  }
  cam_csv.commit();
  summary.frames = frames.size();
  const double duration_s = nsToSeconds(frames.back().t_ns - frames.front().t_ns);
  const double frame_rate_hz =
      frames.size() > 1 && duration_s > 0 ? static_cast<double>(frames.size() - 1) / duration_s : 0.0;

  // imu0: gyroscope before accelerometer.
  {
    CsvFile imu_csv(mav / "imu0" / "data.csv",
                    "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                    "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]");
    io::ImuTextReader imu((seq / "imu.txt").string());
    ImuSample s;
    while (imu.next(s)) {
      row(imu_csv.buffer(), s.t_ns,
          {s.gyro_B.x(), s.gyro_B.y(), s.gyro_B.z(), s.acc_B.x(), s.acc_B.y(), s.acc_B.z()});
      imu_csv.flushIfLarge();
      ++summary.imu_samples;
    }
    imu_csv.commit();
  }

  // Ground truth of the body (IMU) frame, quaternion w first.
  {
    CsvFile gt_csv(mav / "state_groundtruth_estimate0" / "data.csv",
                   "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
                   "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], b_w_RS_S_x [rad s^-1], "
                   "b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], "
                   "b_a_RS_S_z [m s^-2]");
    const auto write = [&](TimeNs t, const Pose& T, const Vec3& v, const Vec3& bg, const Vec3& ba) {
      const Quat& q = T.quaternion();
      const Vec3& p = T.translation();
      row(gt_csv.buffer(), t,
          {p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), v.x(), v.y(), v.z(), bg.x(), bg.y(), bg.z(), ba.x(),
           ba.y(), ba.z()});
      gt_csv.flushIfLarge();
      ++summary.groundtruth_poses;
    };
    const fs::path imu_state = seq / "truth" / "imu_state.txt";
    if (fs::is_regular_file(imu_state)) {
      summary.groundtruth_from_imu_state = true;
      io::ImuStateReader reader(imu_state.string());
      io::ImuTruthState s;
      while (reader.next(s)) write(s.t_ns, s.T_W_B, s.v_W, s.gyro_bias, s.accel_bias);
    } else {
      // T_W_B = T_W_E · T_B_E⁻¹; velocity by central differences over a 3-pose window.
      const Pose T_E_B = event_cam->T_B_C.inverse();
      io::TumReader reader((seq / "groundtruth.txt").string());
      StampedPose window[3];
      int n = 0;
      const auto velocity = [](const StampedPose& a, const StampedPose& b) {
        return Vec3((b.pose.translation() - a.pose.translation()) / nsToSeconds(b.t_ns - a.t_ns));
      };
      StampedPose p;
      while (reader.next(p)) {
        p.pose = p.pose * T_E_B;
        if (n < 3) window[n++] = p;
        else {
          window[0] = window[1];
          window[1] = window[2];
          window[2] = p;
        }
        if (n == 2) write(window[0].t_ns, window[0].pose, velocity(window[0], window[1]), Vec3::Zero(), Vec3::Zero());
        if (n == 3) write(window[1].t_ns, window[1].pose, velocity(window[0], window[2]), Vec3::Zero(), Vec3::Zero());
      }
      if (n >= 2) write(window[n - 1].t_ns, window[n - 1].pose, velocity(window[n - 2], window[n - 1]), Vec3::Zero(),
                        Vec3::Zero());
      else if (n == 1) write(window[0].t_ns, window[0].pose, Vec3::Zero(), Vec3::Zero(), Vec3::Zero());
      summary.warnings.push_back(
          "no truth/imu_state.txt: ground-truth body poses from groundtruth.txt and the event camera's T_B_C, "
          "velocity by finite differences, biases written as 0");
    }
    gt_csv.commit();
  }

  // Camera model in Kalibr's terms.
  const std::string model(cam->camera.model());
  std::string kalibr_model = "pinhole", distortion_model = "radtan";
  std::vector<double> coeffs = {0.0, 0.0, 0.0, 0.0};
  const VecX d = cam->camera.distortion();
  if (model == "radtan") {
    coeffs = {d(0), d(1), d(2), d(3)};
    if (d.size() > 4 && d(4) != 0.0)
      summary.warnings.push_back("camera " + cam->name + ": radtan k3 = " + num(d(4)) +
                                 " dropped (Kalibr's radtan has k1 k2 p1 p2 only)");
  } else if (model == "equidistant") {
    distortion_model = "equidistant";
    coeffs = {d(0), d(1), d(2), d(3)};
  }
  const Vec4 k = cam->camera.intrinsics();
  const std::vector<double> intrinsics = {k(0), k(1), k(2), k(3)};
  const Mat4 T_B_C = cam->T_B_C.matrix();
  const Mat4 T_cam_imu = cam->T_B_C.inverse().matrix();
  const double timeshift_s = nsToSeconds(rig.time_offset_cam_imu_ns);

  {  // mav0/cam0/sensor.yaml
    YAML::Emitter e;
    e << YAML::BeginMap;
    e << YAML::Key << "sensor_type" << YAML::Value << "camera";
    e << YAML::Key << "comment" << YAML::Value << ("evio camera " + cam->name + " (" + std::string(cameraRoleName(cam->role)) + ")");
    e << YAML::Key << "T_BS" << YAML::Value;
    emitEurocMatrix(e, T_B_C);
    e << YAML::Key << "rate_hz" << YAML::Value << num(frame_rate_hz);
    e << YAML::Key << "resolution" << YAML::Value << YAML::Flow << YAML::BeginSeq << cam->camera.width()
      << cam->camera.height() << YAML::EndSeq;
    e << YAML::Key << "camera_model" << YAML::Value << "pinhole";
    e << YAML::Key << "intrinsics" << YAML::Value;
    emitFlow(e, intrinsics);
    e << YAML::Key << "distortion_model" << YAML::Value
      << (distortion_model == "radtan" ? "radial-tangential" : "equidistant");
    e << YAML::Key << "distortion_coefficients" << YAML::Value;
    emitFlow(e, coeffs);
    e << YAML::EndMap;
    writeYaml(mav / "cam0" / "sensor.yaml", e);
  }
  {  // mav0/imu0/sensor.yaml
    YAML::Emitter e;
    e << YAML::BeginMap;
    e << YAML::Key << "sensor_type" << YAML::Value << "imu";
    e << YAML::Key << "comment" << YAML::Value << "evio IMU (the body frame B)";
    e << YAML::Key << "T_BS" << YAML::Value;
    emitEurocMatrix(e, Mat4::Identity());
    e << YAML::Key << "rate_hz" << YAML::Value << num(rig.imu.update_rate);
    e << YAML::Key << "gyroscope_noise_density" << YAML::Value << num(rig.imu.gyroscope_noise_density);
    e << YAML::Key << "gyroscope_random_walk" << YAML::Value << num(rig.imu.gyroscope_random_walk);
    e << YAML::Key << "accelerometer_noise_density" << YAML::Value << num(rig.imu.accelerometer_noise_density);
    e << YAML::Key << "accelerometer_random_walk" << YAML::Value << num(rig.imu.accelerometer_random_walk);
    e << YAML::EndMap;
    writeYaml(mav / "imu0" / "sensor.yaml", e);
  }
  {  // camchain.yaml (Kalibr imu-cam chain)
    YAML::Emitter e;
    e << YAML::BeginMap << YAML::Key << "cam0" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "T_cam_imu" << YAML::Value;
    emitMatrixRows(e, T_cam_imu);
    e << YAML::Key << "cam_overlaps" << YAML::Value << YAML::Flow << YAML::BeginSeq << YAML::EndSeq;
    e << YAML::Key << "camera_model" << YAML::Value << kalibr_model;
    e << YAML::Key << "distortion_coeffs" << YAML::Value;
    emitFlow(e, coeffs);
    e << YAML::Key << "distortion_model" << YAML::Value << distortion_model;
    e << YAML::Key << "intrinsics" << YAML::Value;
    emitFlow(e, intrinsics);
    e << YAML::Key << "resolution" << YAML::Value << YAML::Flow << YAML::BeginSeq << cam->camera.width()
      << cam->camera.height() << YAML::EndSeq;
    e << YAML::Key << "rostopic" << YAML::Value << "/cam0/image_raw";
    e << YAML::Key << "timeshift_cam_imu" << YAML::Value << num(timeshift_s);
    e << YAML::EndMap << YAML::EndMap;
    writeYaml(out / "camchain.yaml", e);
  }
  {  // imu.yaml (Kalibr IMU)
    YAML::Emitter e;
    e << YAML::BeginMap << YAML::Key << "imu0" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "T_i_b" << YAML::Value;
    emitMatrixRows(e, Mat4::Identity());
    e << YAML::Key << "accelerometer_noise_density" << YAML::Value << num(rig.imu.accelerometer_noise_density);
    e << YAML::Key << "accelerometer_random_walk" << YAML::Value << num(rig.imu.accelerometer_random_walk);
    e << YAML::Key << "gyroscope_noise_density" << YAML::Value << num(rig.imu.gyroscope_noise_density);
    e << YAML::Key << "gyroscope_random_walk" << YAML::Value << num(rig.imu.gyroscope_random_walk);
    e << YAML::Key << "model" << YAML::Value << "calibrated";
    // OpenVINS reads the IMU intrinsics even for a calibrated model: the
    // simulator's IMU has unit scale, aligned axes and no g-sensitivity.
    e << YAML::Key << "Tw" << YAML::Value;
    emitMatrixRows3(e, Mat3::Identity());
    e << YAML::Key << "R_IMUtoGYRO" << YAML::Value;
    emitMatrixRows3(e, Mat3::Identity());
    e << YAML::Key << "Ta" << YAML::Value;
    emitMatrixRows3(e, Mat3::Identity());
    e << YAML::Key << "R_IMUtoACC" << YAML::Value;
    emitMatrixRows3(e, Mat3::Identity());
    e << YAML::Key << "Tg" << YAML::Value;
    emitMatrixRows3(e, Mat3::Zero());
    e << YAML::Key << "rostopic" << YAML::Value << "/imu0";
    e << YAML::Key << "time_offset" << YAML::Value << num(0.0);
    e << YAML::Key << "update_rate" << YAML::Value << num(rig.imu.update_rate);
    e << YAML::EndMap << YAML::EndMap;
    writeYaml(out / "imu.yaml", e);
  }
  {  // mav0/body.yaml and the ground truth's sensor.yaml, as in the EuRoC layout
    YAML::Emitter body;
    body << YAML::BeginMap << YAML::Key << "comment" << YAML::Value
         << "The body frame B is the IMU frame; every T_BS is the sensor's pose in it." << YAML::EndMap;
    writeYaml(mav / "body.yaml", body);
    YAML::Emitter gt;
    gt << YAML::BeginMap << YAML::Key << "sensor_type" << YAML::Value << "visual-inertial";
    gt << YAML::Key << "comment" << YAML::Value
       << (summary.groundtruth_from_imu_state
               ? "Exact ground truth of the evio simulator: body pose, velocity and IMU biases."
               : "Body poses from groundtruth.txt and T_B_C; velocity by finite differences; biases 0.");
    gt << YAML::Key << "T_BS" << YAML::Value;
    emitEurocMatrix(gt, Mat4::Identity());
    gt << YAML::EndMap;
    writeYaml(mav / "state_groundtruth_estimate0" / "sensor.yaml", gt);
  }
  // Gravity: EuRoC has no field for it and every peer assumes Earth's unless
  // told, so a Mars sequence would run with the wrong gravity silently.
  // estimator_config.yaml is where OpenVINS reads it (gravity_mag), beside
  // the paths of the two Kalibr files.
  if (std::abs(rig.gravity_m_s2 - kPeerDefaultGravity) > 0.01)
    summary.warnings.push_back("gravity is " + num(rig.gravity_m_s2) +
                               " m/s^2, not Earth's: EuRoC has no field for it; estimator_config.yaml gives it to "
                               "OpenVINS (gravity_mag); set it by hand in any other peer, which assumes 9.81");
  {
    YAML::Emitter e;
    e << YAML::BeginMap;
    e << YAML::Key << "gravity_mag" << YAML::Value << num(rig.gravity_m_s2);
    e << YAML::Key << "relative_config_imu" << YAML::Value << "imu.yaml";
    e << YAML::Key << "relative_config_imucam" << YAML::Value << "camchain.yaml";
    e << YAML::EndMap;
    writeYaml(out / "estimator_config.yaml", e);
  }
  {  // evio_export.yaml
    YAML::Emitter e;
    e << YAML::BeginMap;
    e << YAML::Key << "source" << YAML::Value << fs::absolute(seq).lexically_normal().string();
    e << YAML::Key << "camera" << YAML::Value << cam->name;
    e << YAML::Key << "gravity_m_s2" << YAML::Value << num(rig.gravity_m_s2);
    e << YAML::Key << "frames" << YAML::Value << summary.frames;
    e << YAML::Key << "imu_samples" << YAML::Value << summary.imu_samples;
    e << YAML::Key << "groundtruth_poses" << YAML::Value << summary.groundtruth_poses;
    e << YAML::Key << "groundtruth_from" << YAML::Value
      << (summary.groundtruth_from_imu_state ? "truth/imu_state.txt" : "groundtruth.txt");
    e << YAML::Key << "warnings" << YAML::Value << YAML::BeginSeq;
    for (const auto& w : summary.warnings) e << w;
    e << YAML::EndSeq << YAML::EndMap;
    writeYaml(out / "evio_export.yaml", e);
  }
  return summary;
}

}  // namespace evio::experiments

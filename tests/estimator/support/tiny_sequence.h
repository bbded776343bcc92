#pragma once
/// @file tiny_sequence.h
/// Writes a small sequence folder (docs/architecture.md#the-sequence-folder) for pipeline tests with
/// the core/io writers: the first seconds of the six_dof trajectory preset,
/// IMU from ImuSimulator (Kalibr noise model, DAVIS240 reference densities),
/// groundtruth.txt (T_W_C of the camera), exact ground-truth tracks of a
/// static landmark cloud in front of the camera (truth/tracks.txt, visible
/// samples only), sensors.yaml or calib.txt, and optionally frames (a
/// deterministic texture, any size) and a few events. Bad-input variants:
/// IMU gaps, a shorter imu.txt. Randomness: RandomStream(seed, "landmarks"),
/// the simulator's IMU streams.

#include <cmath>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "evio/core/io/calib_txt.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/random_stream.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio::test {

struct TinySequenceOptions {
  double duration_s = 4.0;
  double imu_rate_hz = 200.0;
  double groundtruth_rate_hz = 100.0;   ///< also the rate of truth/tracks.txt
  int landmarks = 300;
  bool sensors_yaml = true;             ///< else calib.txt only
  bool groundtruth = true;
  bool tracks = true;
  int frames = 0;                       ///< frames over the duration (0: no images.txt)
  int frame_width = 240, frame_height = 180;
  bool events = false;                  ///< a few events per millisecond (events.txt)
  std::vector<std::pair<double, double>> imu_gaps_s;  ///< [t0, t1) without IMU readings
  double imu_end_s = -1.0;              ///< imu.txt ends here (< 0: at the end)
  Vec3 gyro_bias_radps = Vec3::Zero();  ///< the simulated gyroscope's bias at the start
  std::string trajectory_preset = "six_dof.yaml";  ///< from trajectories/presets (flight.yaml: 2 s at rest first)
  std::uint64_t seed = 1;
};

inline Camera tinyCamera() { return Camera::create("pinhole", 240, 180, Vec4(200.0, 200.0, 120.0, 90.0), VecX()); }

/// Camera z along B's x (forward), x along −y of B, y along −z of B, with a lever arm.
inline Pose tinyT_B_C() {
  Mat3 R_B_C;
  R_B_C.col(0) = Vec3(0, -1, 0);
  R_B_C.col(1) = Vec3(0, 0, -1);
  R_B_C.col(2) = Vec3(1, 0, 0);
  return Pose(R_B_C, Vec3(0.03, -0.01, 0.02));
}

inline ImuSimulator::Options tinyImuOptions(double rate_hz) {
  ImuSimulator::Options o;
  o.update_rate_hz = rate_hz;
  o.gravity_mps2 = 9.81;
  return o;
}

inline SensorRig tinyRig(double imu_rate_hz) {
  SensorRig rig;
  rig.cameras.push_back(CameraSensor{"cam0", CameraRole::kEvent, tinyCamera(), tinyT_B_C(), {}});
  rig.cameras.push_back(CameraSensor{"frames", CameraRole::kFrame, tinyCamera(), tinyT_B_C(), {}});
  const ImuSimulator::Options o = tinyImuOptions(imu_rate_hz);
  rig.imu.accelerometer_noise_density = o.accelerometer_noise_density;
  rig.imu.accelerometer_random_walk = o.accelerometer_random_walk;
  rig.imu.gyroscope_noise_density = o.gyroscope_noise_density;
  rig.imu.gyroscope_random_walk = o.gyroscope_random_walk;
  rig.imu.update_rate = imu_rate_hz;
  rig.gravity_m_s2 = o.gravity_mps2;
  return rig;
}

/// The body trajectory of the tiny sequences (by default the six_dof preset, 60 s long).
inline std::unique_ptr<ContinuousTrajectory> tinyTrajectory(const std::string& preset = "six_dof.yaml") {
  return makeTrajectory(trajectoryPresetPath(preset));
}

inline void writeTinySequence(const std::string& folder, const TinySequenceOptions& o) {
  namespace fs = std::filesystem;
  fs::create_directories(fs::path(folder) / "truth");
  const auto traj = tinyTrajectory(o.trajectory_preset);
  const TimeNs t0 = traj->startTime();
  const TimeNs t_end = t0 + secondsToNs(o.duration_s);
  const Camera camera = tinyCamera();
  const Pose T_B_C = tinyT_B_C();
  const auto path = [&](const std::string& name) { return (fs::path(folder) / name).string(); };

  if (o.sensors_yaml) io::writeSensorsYaml(path("sensors.yaml"), tinyRig(o.imu_rate_hz));
  else io::writeCalibTxt(path("calib.txt"), io::calibTxtFromCamera(camera));

  // IMU.
  ImuSimulator::Options imu_options = tinyImuOptions(o.imu_rate_hz);
  imu_options.gyroscope_initial_bias_radps = o.gyro_bias_radps;
  ImuSimulator sim(*traj, imu_options, o.seed);
  ImuSamples imu;
  ImuMeasurement m;
  const TimeNs imu_end = o.imu_end_s >= 0.0 ? t0 + secondsToNs(o.imu_end_s) : t_end;
  while (sim.next(m) && m.sample.t_ns <= imu_end) {
    bool in_gap = false;
    for (const auto& [a, b] : o.imu_gaps_s)
      in_gap = in_gap || (m.sample.t_ns >= t0 + secondsToNs(a) && m.sample.t_ns < t0 + secondsToNs(b));
    if (!in_gap) imu.push_back(m.sample);
  }
  io::writeImuText(path("imu.txt"), imu);

  // Ground truth and tracks.
  const TimeNs dt = secondsToNs(1.0 / o.groundtruth_rate_hz);
  Trajectory gt;
  for (TimeNs t = t0; t <= t_end; t += dt) gt.push_back(StampedPose{t, traj->evaluate(t).T_W_B * T_B_C});
  if (o.groundtruth) io::writeTum(path("groundtruth.txt"), gt);
  if (o.tracks) {
    RandomStream rng(o.seed, "landmarks");
    std::vector<Vec3> landmarks_W;
    const Pose& T_W_C0 = gt.front().pose;
    while (static_cast<int>(landmarks_W.size()) < o.landmarks) {
      const Vec2 uv(rng.uniform(0.0, 240.0), rng.uniform(0.0, 180.0));
      Vec3 bearing;
      if (!camera.unproject(uv, &bearing)) continue;
      const double depth = rng.uniform(2.0, 5.0);
      landmarks_W.push_back(T_W_C0 * (bearing / bearing.z() * depth));
    }
    std::vector<io::TrackSample> samples;
    for (const StampedPose& p : gt) {
      const Pose T_C_W = p.pose.inverse();
      for (std::size_t i = 0; i < landmarks_W.size(); ++i) {
        const Vec3 p_C = T_C_W * landmarks_W[i];
        Vec2 uv;
        if (p_C.z() < 0.2 || !camera.project(p_C, &uv) || !camera.isInside(uv)) continue;
        samples.push_back(io::TrackSample{static_cast<std::int64_t>(i), p.t_ns, uv});
      }
    }
    io::writeTracksText(path("truth/tracks.txt"), samples);
  }

  if (o.frames > 0) {
    io::ImageFolderWriter frames(folder);
    cv::Mat image(o.frame_height, o.frame_width, CV_8UC1);
    RandomStream rng(o.seed, "frames");
    for (int r = 0; r < image.rows; ++r)
      for (int c = 0; c < image.cols; ++c)
        image.at<std::uint8_t>(r, c) = static_cast<std::uint8_t>(rng.uniformInt(256));
    for (int k = 0; k < o.frames; ++k)
      frames.append(t0 + static_cast<TimeNs>(static_cast<double>(k) / o.frames * static_cast<double>(t_end - t0)), image);
    frames.close();
  }
  if (o.events) {
    EventArray events;
    for (TimeNs t = t0; t < t_end; t += kNsPerMs)
      events.push_back(t, static_cast<std::uint16_t>((t / kNsPerMs) % 240), static_cast<std::uint16_t>((t / kNsPerMs) % 180),
                       ((t / kNsPerMs) % 2) == 0);
    io::writeEventsText(path("events.txt"), events);
  }
}

}  // namespace evio::test

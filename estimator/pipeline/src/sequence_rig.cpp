#include "evio/estimator/pipeline/sequence_rig.h"

#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/sensors_yaml.h"

namespace evio::estimator {

namespace fs = std::filesystem;

std::string SequenceRig::describe(const CameraSensor& camera) const {
  if (source == "sensors.yaml") return "sensors.yaml camera " + camera.name;
  return source;
}

SequenceRig loadSequenceRig(const std::string& folder, const CalibrationOptions& calibration,
                            const BackendOptions& backend, std::optional<cv::Size> first_frame_size) {
  calibration.validate();
  SequenceRig out;
  const fs::path sensors = fs::path(folder) / "sensors.yaml";
  const fs::path calib = fs::path(folder) / "calib.txt";
  if (fs::exists(sensors)) {
    out.rig = io::readSensorsYaml(sensors.string());
    out.source = "sensors.yaml";
  } else if (fs::exists(calib)) {
    int width = calibration.width, height = calibration.height;
    if (width == 0) {
      if (!first_frame_size)
        throw Error(folder + ": calib.txt holds no sensor size and there are no frames; set calibration.width "
                             "and calibration.height");
      width = first_frame_size->width;
      height = first_frame_size->height;
    }
    CameraSensor cam{"calib.txt", CameraRole::kEvent,
                     io::cameraFromCalibTxt(io::readCalibTxt(calib.string()), width, height),
                     Pose(Mat3(calibration.T_B_C.topLeftCorner<3, 3>()), Vec3(calibration.T_B_C.topRightCorner<3, 1>())),
                     {}};
    out.rig.cameras.push_back(std::move(cam));
    out.rig.imu.accelerometer_noise_density = backend.accelerometer_noise_density;
    out.rig.imu.accelerometer_random_walk = backend.accelerometer_random_walk;
    out.rig.imu.gyroscope_noise_density = backend.gyroscope_noise_density;
    out.rig.imu.gyroscope_random_walk = backend.gyroscope_random_walk;
    out.rig.imu.update_rate = calibration.imu_rate_hz;
    out.rig.gravity_m_s2 = calibration.gravity_mps2;
    out.rig.time_offset_cam_imu_ns = secondsToNs(calibration.time_offset_cam_imu_s);
    out.rig.validate();
    out.source = "calib.txt";
  } else {
    throw Error(folder + ": neither sensors.yaml nor calib.txt");
  }
  const auto indexOf = [&](const CameraSensor* c) { return static_cast<std::size_t>(c - out.rig.cameras.data()); };
  const CameraSensor* event = out.rig.firstCamera(CameraRole::kEvent);
  const CameraSensor* frame = out.rig.firstCamera(CameraRole::kFrame);
  out.event_index = event != nullptr ? indexOf(event) : 0;
  out.frame_index = frame != nullptr ? indexOf(frame) : out.event_index;
  return out;
}

}  // namespace evio::estimator

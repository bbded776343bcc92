#pragma once
/// @file sensor_rig.h
/// The sensor rig of a sequence: cameras (event and frame) with their models
/// and extrinsics, the IMU noise model, gravity, an optional laser range
/// finder and the camera–IMU time offset. Stored as sensors.yaml
/// (core/io/sensors_yaml.h).
///
/// Frames: B is the body = IMU frame; C a camera frame (camera_common.h);
/// L the range finder frame, whose +z axis is the beam. T_B_C maps points
/// from C into B: p_B = T_B_C · p_C.

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/core/pose.h"
#include "evio/core/time.h"

namespace evio {

/// What a camera delivers: an event stream or intensity frames.
enum class CameraRole { kEvent, kFrame };

/// "event" or "frame".
std::string_view cameraRoleName(CameraRole role);

/// Inverse of cameraRoleName; throws evio::Error "role: ..." for other text.
CameraRole parseCameraRole(std::string_view name);

/// One camera of the rig.
struct CameraSensor {
  std::string name;                        ///< unique in the rig, e.g. "cam0"
  CameraRole role = CameraRole::kEvent;    ///< event or frame camera
  Camera camera;                           ///< model, resolution, intrinsics, distortion
  Pose T_B_C;                              ///< camera frame C into body (IMU) frame B
  /// Further scalar properties, an open set: for event cameras e.g.
  /// contrast_threshold_pos, contrast_threshold_neg, refractory_period_s;
  /// for frame cameras e.g. exposure_s. Names should carry their unit.
  std::map<std::string, double> parameters;
};

/// IMU noise model in Kalibr's names and units (continuous-time densities).
/// All fields must be given; noise values are finite and >= 0.
struct ImuSensor {
  double accelerometer_noise_density = 0.0;  ///< white noise, m/s² /√Hz
  double accelerometer_random_walk = 0.0;    ///< bias random walk, m/s³ /√Hz
  double gyroscope_noise_density = 0.0;      ///< white noise, rad/s /√Hz
  double gyroscope_random_walk = 0.0;        ///< bias random walk, rad/s² /√Hz
  double update_rate = 0.0;                  ///< sample rate, Hz (> 0)

  /// Throws evio::Error naming the field ("imu.gyroscope_noise_density: ...").
  void validate() const;
};

/// A single-beam laser range finder measuring the distance along +z of L.
struct RangeFinderSensor {
  Pose T_B_L;                  ///< range finder frame L into body frame B
  double min_range_m = 0.0;    ///< shortest measurable range, m (>= 0)
  double max_range_m = 0.0;    ///< longest measurable range, m (> min_range_m)
  double noise_sigma_m = 0.0;  ///< standard deviation of the range noise, m (>= 0)

  /// Throws evio::Error naming the field ("range_finder.max_range_m: ...").
  void validate() const;
};

struct SensorRig {
  std::vector<CameraSensor> cameras;  ///< at least one; names unique
  ImuSensor imu;
  double gravity_m_s2 = 0.0;          ///< magnitude of gravity, m/s² (Mars: 3.721)
  std::optional<RangeFinderSensor> range_finder;
  /// Camera–IMU time offset, Kalibr's timeshift_cam_imu: a camera stamp t_cam
  /// corresponds to the IMU clock time t_imu = t_cam + time_offset_cam_imu_ns.
  TimeNs time_offset_cam_imu_ns = 0;

  /// Throws evio::Error naming the field unless: at least one camera, names
  /// non-empty and unique, camera parameters finite with non-empty names, the
  /// IMU and range finder valid, gravity finite and > 0.
  void validate() const;

  /// The camera named `name`, or nullptr.
  const CameraSensor* findCamera(std::string_view name) const;
  /// The first camera with `role`, or nullptr.
  const CameraSensor* firstCamera(CameraRole role) const;
};

}  // namespace evio

#include "evio/core/sensor_rig.h"

#include <cmath>
#include <set>

#include "evio/core/error.h"
#include "evio/core/options.h"

namespace evio {

std::string_view cameraRoleName(CameraRole role) {
  return role == CameraRole::kEvent ? "event" : "frame";
}

CameraRole parseCameraRole(std::string_view name) {
  if (name == "event") return CameraRole::kEvent;
  if (name == "frame") return CameraRole::kFrame;
  throw Error("role: expected 'event' or 'frame', got '" + std::string(name) + "'");
}

void ImuSensor::validate() const {
  requireNonNegative("imu.accelerometer_noise_density", accelerometer_noise_density);
  requireNonNegative("imu.accelerometer_random_walk", accelerometer_random_walk);
  requireNonNegative("imu.gyroscope_noise_density", gyroscope_noise_density);
  requireNonNegative("imu.gyroscope_random_walk", gyroscope_random_walk);
  requirePositive("imu.update_rate", update_rate);
  requireInRange("imu.update_rate", update_rate, 0.0, 1e5);
}

void RangeFinderSensor::validate() const {
  requireNonNegative("range_finder.min_range_m", min_range_m);
  requirePositive("range_finder.max_range_m", max_range_m);
  requireField(max_range_m > min_range_m, "range_finder.max_range_m",
               "must be greater than min_range_m");
  requireNonNegative("range_finder.noise_sigma_m", noise_sigma_m);
}

void SensorRig::validate() const {
  requireField(!cameras.empty(), "cameras", "at least one camera is required");
  std::set<std::string> names;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    const CameraSensor& c = cameras[i];
    const std::string field = "cameras[" + std::to_string(i) + "]";
    requireField(!c.name.empty(), field + ".name", "must not be empty");
    requireField(names.insert(c.name).second, field + ".name",
                 "duplicate camera name '" + c.name + "'");
    for (const auto& [key, value] : c.parameters) {
      requireField(!key.empty(), field + ".parameters", "empty parameter name");
      requireField(std::isfinite(value), field + ".parameters." + key, "must be finite");
    }
  }
  imu.validate();
  requirePositive("gravity_m_s2", gravity_m_s2);
  if (range_finder) range_finder->validate();
}

const CameraSensor* SensorRig::findCamera(std::string_view name) const {
  for (const auto& c : cameras)
    if (c.name == name) return &c;
  return nullptr;
}

const CameraSensor* SensorRig::firstCamera(CameraRole role) const {
  for (const auto& c : cameras)
    if (c.role == role) return &c;
  return nullptr;
}

}  // namespace evio

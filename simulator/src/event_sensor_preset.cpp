#include "evio/simulator/event_sensor_preset.h"

#include "evio/core/io/config.h"

namespace evio::simulator {

void EventSensorPreset::validate() const {
  requireField(!name.empty(), "name", "must not be empty");
  requireInRange("width", width, 1, 65536);
  requireInRange("height", height, 1, 65536);
  for (int i = 0; i < 4; ++i) requirePositive("intrinsics", intrinsics(i));
  requirePositive("pixel_pitch_um", pixel_pitch_um);
  try {
    event_camera.validate();
  } catch (const Error& e) {
    throw Error(std::string("event_camera.") + e.what());
  }
}

EventSensorPreset loadEventSensorPreset(const std::string& path, const std::vector<std::string>& overrides) {
  return config::load<EventSensorPreset>(path, overrides);
}

}  // namespace evio::simulator

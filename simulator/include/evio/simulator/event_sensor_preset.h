#pragma once
/// @file event_sensor_preset.h
/// Presets for real event sensors (simulator/presets/*.yaml): resolution,
/// typical pinhole intrinsics, pixel pitch and the EventCamera options
/// (thresholds, mismatch, refractory period, bandwidth, noise rates). Each
/// YAML file states its sources in comments.

#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"
#include "evio/simulator/event_camera.h"

namespace evio::simulator {

struct EventSensorPreset {
  std::string name;                       ///< sensor name, e.g. "DAVIS240C"
  int width = 0;                          ///< pixels
  int height = 0;                         ///< pixels
  Vec4 intrinsics = Vec4::Zero();         ///< typical fx fy cx cy (px) of a lens used with it
  double pixel_pitch_um = 0.0;            ///< pixel pitch, µm
  EventCamera::Options event_camera;      ///< the pixel model

  template <class V>
  void fields(V& v) {
    v("name", name, "sensor name");
    v("width", width, "width, px");
    v("height", height, "height, px");
    v("intrinsics", intrinsics, "typical fx fy cx cy, px");
    v("pixel_pitch_um", pixel_pitch_um, "pixel pitch, um");
    v("event_camera", event_camera, "event camera options");
  }
  void validate() const;
};

/// Loads a preset file; `overrides` are "a.b=value" (config.h). Throws
/// evio::Error naming the file, line and field.
EventSensorPreset loadEventSensorPreset(const std::string& path, const std::vector<std::string>& overrides = {});

}  // namespace evio::simulator

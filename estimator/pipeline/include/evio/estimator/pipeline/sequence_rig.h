#pragma once
/// @file sequence_rig.h
/// The sensor rig of a sequence folder: sensors.yaml when present (simulated
/// sequences), else calib.txt (recorded Event-Camera Dataset folders) with
/// the rest from the configuration: T_B_C, gravity and time offset from
/// CalibrationOptions, IMU noise densities from BackendOptions. A calib.txt
/// rig has one camera, "calib.txt", which is both the event and the frame
/// camera (one DAVIS sensor); its size comes from the calibration options or
/// else from the first frame.

#include <cstddef>
#include <optional>
#include <string>

#include <opencv2/core/types.hpp>

#include "evio/core/sensor_rig.h"
#include "evio/estimator/backend/backend_options.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {

struct SequenceRig {
  SensorRig rig;
  std::string source;                   ///< "sensors.yaml" or "calib.txt"
  std::size_t event_index = 0;          ///< the event camera in rig.cameras (the first event camera, else the first)
  std::size_t frame_index = 0;          ///< the first frame camera, else the event camera

  const CameraSensor& eventCamera() const { return rig.cameras.at(event_index); }
  const CameraSensor& frameCamera() const { return rig.cameras.at(frame_index); }

  /// "sensors.yaml camera cam0" / "calib.txt": where a camera's size came from, for messages.
  std::string describe(const CameraSensor& camera) const;
};

/// Loads the rig of `folder`. `first_frame_size` is the size of the first
/// frame when there are frames (used only for calib.txt). Throws evio::Error
/// when neither sensors.yaml nor calib.txt exists, when a calib.txt folder
/// has neither frames nor calibration.width/height, or when a file is
/// malformed (errors name file and line).
SequenceRig loadSequenceRig(const std::string& folder, const CalibrationOptions& calibration,
                            const BackendOptions& backend, std::optional<cv::Size> first_frame_size);

}  // namespace evio::estimator

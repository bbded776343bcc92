#pragma once
/// @file track_sequence.h
/// Runs a frontend (estimator/frontend/frontend.h) over a sequence folder
/// (docs/architecture.md#the-sequence-folder), interleaving events, frames
/// and IMU samples by time, and collects the feature tracks.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "evio/core/io/track_noise_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/estimator/frontend/frontend.h"

namespace evio::experiments {

struct TrackSequenceResult {
  std::vector<io::TrackSample> samples;  ///< new and tracked points, in production order
  std::vector<io::TrackNoiseSample> noise;  ///< sample by sample, its quality and covariance as the tracker stated them
  std::uint64_t events = 0;              ///< events read
  std::uint64_t events_kept = 0;         ///< after the pre-filters
  std::uint64_t frames = 0;              ///< sensor frames read
  std::uint64_t reconstructed_frames = 0;
  std::uint64_t tracks = 0;              ///< distinct track ids
  double processing_s = 0.0;             ///< wall time inside the frontend
  std::string camera_name;               ///< the camera whose pixels the tracks are in
  estimator::FrontendOptions options;    ///< as run: the sensor's thresholds filled in (resolveSensorParameters)
};

/// Called with the share of events read (0..1) and the number read.
using TrackProgress = std::function<void(double fraction, std::uint64_t events)>;

/// The camera comes from sensors.yaml (EKLT: the event camera, KLT: the
/// frame camera when there is one) or else from calib.txt with the size of
/// the first frame. Events from events.h5 when present, else events.txt.
/// IMU (imu.txt) is read only when the EKLT gyro prediction is on.
/// Throws evio::Error for a missing or malformed input.
TrackSequenceResult trackSequence(const std::string& folder, const estimator::FrontendOptions& options,
                                  const TrackProgress& progress = {});

}  // namespace evio::experiments

#pragma once
/// @file track_sequence.h
/// Runs a frontend (estimator/frontend/frontend.h) over a sequence folder
/// (docs/architecture.md#the-sequence-folder), interleaving events, frames
/// and IMU samples by time, and collects the feature tracks.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/io/track_noise_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/estimator/frontend/frontend.h"
#include "evio/estimator/frontend/track_lag.h"

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
  /// With compensate_lag: the samples moved forward by the lag estimated
  /// online so far (lagCompensated), else empty.
  std::vector<io::TrackSample> compensated;
};

/// Called with the share of events read (0..1) and the number read.
using TrackProgress = std::function<void(double fraction, std::uint64_t events)>;

/// What trackSequence's `compensate_lag` asks for: each track's velocity
/// fitted over this window, s (synchronizer.h velocity_window_s; 0: its
/// newest two points).
struct LagCompensation {
  double velocity_window_s = 0.0;
};

/// The camera comes from sensors.yaml (EKLT: the event camera, KLT: the
/// frame camera when there is one) or else from calib.txt with the size of
/// the first frame. Events from events.h5 when present, else events.txt.
/// IMU (imu.txt) is read only when the EKLT gyro prediction is on.
/// Throws evio::Error for a missing or malformed input.
/// With `compensate_lag`, also fills `compensated`: what the filter is
/// given for each point once the frontend's online lag estimate (track_lag)
/// exists. Unlike the synchroniser, a second point at a track's newest time
/// is dropped (tracks.txt needs increasing times), not put in its place.
TrackSequenceResult trackSequence(const std::string& folder, const estimator::FrontendOptions& options,
                                  const TrackProgress& progress = {},
                                  std::optional<LagCompensation> compensate_lag = std::nullopt);

/// A track point moved forward by the lag a + τ|v| along its velocity v
/// (px/s): uv + τ v + a v/|v| (the synchroniser's compensation,
/// estimator/frontend/synchronizer.h, at the point's own time instead of
/// the set's). A still point (v = 0) is returned unchanged.
Vec2 lagCompensated(const estimator::TrackLag& lag, const Vec2& uv, const Vec2& velocity);

}  // namespace evio::experiments

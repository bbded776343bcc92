#pragma once
/// @file feature_tracker.h
/// The interface every frontend tracker implements (EKLT, KLT, HASTE), so that the
/// synchronizer and the backend pipelines treat them alike.
///
/// Inputs must come in time order across all three streams: the caller
/// interleaves events, frames and IMU samples by timestamp (events with
/// t < t_frame before the frame at t_frame).

#include <cstddef>
#include <string_view>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/event.h"
#include "evio/core/imu_sample.h"
#include "evio/estimator/frontend/worker_pool.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

class FeatureTracker {
 public:
  virtual ~FeatureTracker() = default;

  /// A frame at time t_ns: CV_8UC1 intensity, or CV_32FC1 taken as a log
  /// image already (e.g. from ImageReconstructor). Size must be the camera's.
  virtual void addFrame(TimeNs t_ns, const cv::Mat& image) = 0;

  /// Events [begin, end) of `events` (non-decreasing time). No-op for
  /// frame-only trackers.
  virtual void addEvents(const EventArray& events, std::size_t begin, std::size_t end) = 0;
  void addEvents(const EventArray& events) { addEvents(events, 0, events.size()); }

  /// Events [0, chunk_ends.back()) that arrived as the consecutive chunks
  /// [0, e0), [e0, e1), … of one segment: the same as addEvents and
  /// drainTrackPoints chunk by chunk (the points of chunk j go to `out`,
  /// out.size() after them to `point_ends`), with nothing else in between.
  /// Trackers with features in parallel track the whole segment in one run
  /// of their threads; this default goes chunk by chunk.
  virtual void addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends, TrackPoints& out,
                              std::vector<std::size_t>& point_ends) {
    std::size_t begin = 0;
    for (const std::size_t end : chunk_ends) {
      addEvents(events, begin, end);
      drainTrackPoints(out);
      point_ends.push_back(out.size());
      begin = end;
    }
  }

  /// True when addImu changes what the tracker does with later events (a
  /// gyro prediction): then the IMU's place among the events matters, and
  /// chunks separated by IMU samples cannot be tracked as one segment.
  virtual bool usesImu() const { return false; }

  /// One gyro/accelerometer sample (used for feature prediction when enabled).
  virtual void addImu(const ImuSample& sample) = 0;

  /// Moves the track points produced since the last call into `out`
  /// (appended, in the order they were produced).
  virtual void drainTrackPoints(TrackPoints& out) = 0;

  /// Number of tracks currently alive (being tracked).
  virtual std::size_t numAlive() const = 0;

  /// "eklt", "klt" or "haste".
  virtual std::string_view name() const = 0;

  /// CPU time of the features tracked in parallel so far (worker_pool.h);
  /// zeros for a tracker on one thread.
  virtual WorkerPool::Cpu parallelCpu() const { return {}; }
};

}  // namespace evio::estimator

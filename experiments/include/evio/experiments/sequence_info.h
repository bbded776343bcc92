#pragma once
/// @file sequence_info.h
/// What a sequence folder (docs/architecture.md#the-sequence-folder,
/// Event-Camera Dataset layout) contains: durations, resolution,
/// event/IMU/frame/ground-truth counts and rates, and which files are missing.
/// Everything is streamed; memory is flat.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/time.h"

namespace evio::experiments {

struct StreamStats {
  bool present = false;
  std::string file;             ///< the file the numbers come from
  std::uint64_t count = 0;
  TimeNs t_first_ns = 0;
  TimeNs t_last_ns = 0;
  double durationS() const { return nsToSeconds(t_last_ns - t_first_ns); }
  /// Mean rate count/duration in Hz (0 when fewer than 2 samples).
  double meanRateHz() const;
};

struct SequenceInfo {
  std::string folder;
  /// Sensor size and where it came from ("sensors.yaml", "first frame",
  /// "events (max x, y + 1)"), or 0 with source "unknown".
  int width = 0;
  int height = 0;
  std::string resolution_source = "unknown";

  StreamStats events;
  /// Peak event rate over `peak_window_ms` windows, events/s.
  double peak_event_rate_hz = 0.0;
  int peak_window_ms = 10;

  StreamStats imu;
  StreamStats frames;
  StreamStats groundtruth;
  double groundtruth_path_length_m = 0.0;

  bool has_calib = false;
  bool has_sensors_yaml = false;
  bool has_scenario = false;
  bool has_truth = false;

  /// Files of the layout that are absent.
  std::vector<std::string> missing;

  /// Overall time span covered by any stream.
  double durationS() const;
};

/// Called while counting events with the share done (0..1) and the number of
/// events read so far.
using ProgressCallback = std::function<void(double fraction, std::uint64_t events)>;

/// Inspects `folder`. Reads events from events.h5 when present (fast), else
/// events.txt; validates everything it reads (a malformed file is an
/// evio::Error naming the file and line). Throws if the folder does not exist.
SequenceInfo inspectSequence(const std::string& folder, const ProgressCallback& progress = {});

/// A human-readable multi-line report.
std::string formatSequenceInfo(const SequenceInfo& info);

/// The same as a JSON object.
std::string sequenceInfoJson(const SequenceInfo& info);

}  // namespace evio::experiments

#pragma once
/// @file timing_txt.h
/// `timing.txt`: how fast an estimator ran, written by the estimator beside
/// its trajectory and read by `evio evaluate` for the real-time factor (RTF).
/// One line per progress report, 4 columns (files written before the
/// features column have the first 3; the reader accepts both, every row of
/// a file with the same count):
///   t  processing_s  events  features
/// - t: data time in seconds on the sequence clock (the clock of
///   groundtruth.txt): every input with a stamp <= t has been processed.
/// - processing_s: wall-clock seconds the estimator has spent processing
///   since its first line, cumulative (the first line may be > 0 when it
///   counts start-up work).
/// - events: number of events consumed so far, cumulative (0 for frame-based
///   methods).
/// - features: number of features in the latest measurement set the filter
///   received at or before t (what it tracked then; 0 before the first set).
/// The first line is written when the estimator has initialised (RTF is
/// measured after initialisation); later lines at least every 0.2 s of data
/// time (e.g. after every filter update). t increases strictly,
/// processing_s and events never decrease; events and features are whole
/// numbers >= 0.
/// Example:
///   # t processing_s events features
///   0.500000000 0.012 0 0
///   0.600000000 0.061 48211 42

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/io/timed_table.h"

namespace evio::io {

/// One row of timing.txt.
struct TimingSample {
  TimeNs t_ns = 0;            ///< data time, sequence clock
  double processing_s = 0.0;  ///< cumulative wall-clock processing time, s
  std::int64_t events = 0;    ///< cumulative events processed
  /// Features of the latest measurement set at or before t; empty when the
  /// file predates the column (3 columns).
  std::optional<std::int64_t> features;

  friend bool operator==(const TimingSample&, const TimingSample&) = default;
};

/// Streams rows; validates columns, finite numbers, strictly increasing t,
/// processing_s >= 0 and non-decreasing, events a whole number >= 0 and
/// non-decreasing, features a whole number >= 0 (errors name file, line and
/// column).
class TimingReader {
 public:
  explicit TimingReader(std::string path);
  bool next(TimingSample& sample);

 private:
  TimedTableReader table_;
  TimingSample last_;
  bool any_ = false;
};

std::vector<TimingSample> readTimingText(const std::string& path);

/// Streams rows into timing.txt (4 columns), atomically on close(). Throws
/// evio::Error when a row breaks the rules above or has no features count
/// (the writer is the estimator's check).
class TimingWriter {
 public:
  explicit TimingWriter(std::string path);
  void append(const TimingSample& sample);
  void close();

 private:
  TimedTableWriter table_;
  TimingSample last_;
  bool any_ = false;
};

void writeTimingText(const std::string& path, const std::vector<TimingSample>& samples);

}  // namespace evio::io

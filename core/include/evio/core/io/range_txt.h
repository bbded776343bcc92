#pragma once
/// @file range_txt.h
/// `range.txt`: the readings of a single-beam laser range finder, one line
/// per measurement, 3 columns:
///   t  range_m  valid
/// t in seconds on the camera clock (the simulator's true time; imu.txt is
/// stamped on the IMU clock, t_imu = t_cam + time_offset_cam_imu); valid = 1:
/// range_m is the measured range along the beam
/// (m, >= 0); valid = 0: no return (no surface, or the surface closer than
/// the minimum or farther than the maximum range), range_m is written as 0
/// and means nothing. Every measurement has a line, so the sample clock is
/// visible. Time increases strictly.

#include <string>
#include <vector>

#include "evio/core/io/timed_table.h"

namespace evio::io {

/// One row of range.txt.
struct RangeSample {
  TimeNs t_ns = 0;
  double range_m = 0.0;  ///< measured range, m (0 when !valid)
  bool valid = false;    ///< a return was measured

  friend bool operator==(const RangeSample&, const RangeSample&) = default;
};

/// Streams rows; validates the columns, finite numbers, strictly increasing
/// time, valid ∈ {0, 1} and range_m >= 0 (errors name file, line, column).
class RangeReader {
 public:
  explicit RangeReader(std::string path);
  bool next(RangeSample& sample);

 private:
  TimedTableReader table_;
};

std::vector<RangeSample> readRangeText(const std::string& path);

/// Streams rows into the file, atomically on close(). Ranges are written in
/// shortest round-trip form; a sample without a return is written with range 0.
class RangeWriter {
 public:
  explicit RangeWriter(std::string path, const std::vector<std::string>& header = {});
  void append(const RangeSample& sample);
  void close();

 private:
  TimedTableWriter table_;
};

void writeRangeText(const std::string& path, const std::vector<RangeSample>& samples,
                    const std::vector<std::string>& header = {});

}  // namespace evio::io

#pragma once
/// @file imu_txt.h
/// `imu.txt` of the Event-Camera Dataset: `t ax ay az gx gy gz` per line,
/// t in seconds, acceleration (specific force) in m/s² before angular rate in
/// rad/s, both in the IMU frame. (EuRoC's csv has gyro first; not this one.)

#include <string>

#include "evio/core/imu_sample.h"
#include "evio/core/io/timed_table.h"

namespace evio::io {

/// Streams IMU samples; validates columns, numbers and strictly increasing time.
class ImuTextReader {
 public:
  explicit ImuTextReader(std::string path);
  /// Next sample; false at the end.
  bool next(ImuSample& sample);

 private:
  TimedTableReader table_;
};

ImuSamples readImuText(const std::string& path);

/// Streams IMU samples into imu.txt, atomically on close().
class ImuTextWriter {
 public:
  explicit ImuTextWriter(std::string path);
  void append(const ImuSample& sample);
  void close();

 private:
  TimedTableWriter table_;
};

void writeImuText(const std::string& path, const ImuSamples& samples);

}  // namespace evio::io

#pragma once
/// @file tum.h
/// TUM trajectories: `t tx ty tz qx qy qz qw` per line (t in seconds,
/// position in metres, Hamilton quaternion x y z w), '#' comments allowed.
/// `groundtruth.txt` of the Event-Camera Dataset is this format.
///
/// The covariance-carrying variant is the one OpenVINS' ov_eval reads: the
/// eight TUM columns followed by the upper triangles (row-major: 11 12 13 22
/// 23 33) of the 3×3 orientation covariance (rad², in the frame of the
/// estimate's own rotation error convention) and the 3×3 position covariance (m²).

#include <string>
#include <vector>

#include "evio/core/io/timed_table.h"
#include "evio/core/pose.h"

namespace evio::io {

/// A pose with 3×3 orientation and position covariance blocks.
struct StampedPoseCovariance {
  TimeNs t_ns = 0;
  Pose pose;
  Mat3 cov_orientation = Mat3::Zero();  ///< rad²
  Mat3 cov_position = Mat3::Zero();     ///< m²
};

/// Streams poses from a TUM file. Quaternions must have unit norm within 1 %
/// (they are normalised); others are an error naming the line.
class TumReader {
 public:
  explicit TumReader(std::string path);
  bool next(StampedPose& pose);

 private:
  TimedTableReader table_;
};

Trajectory readTum(const std::string& path);

/// Streams poses into a TUM file, atomically on close().
class TumWriter {
 public:
  explicit TumWriter(std::string path, const std::vector<std::string>& header = {});
  void append(const StampedPose& pose);
  void close();

 private:
  TimedTableWriter table_;
};

void writeTum(const std::string& path, const Trajectory& trajectory,
              const std::vector<std::string>& header = {});

/// Reads the covariance variant; covariances must be symmetric positive
/// semi-definite (eigenvalues >= -1e-12·trace) or the line is an error.
std::vector<StampedPoseCovariance> readTumCovariance(const std::string& path);

void writeTumCovariance(const std::string& path, const std::vector<StampedPoseCovariance>& poses,
                        const std::vector<std::string>& header = {});

}  // namespace evio::io

#pragma once
/// @file imu_state_txt.h
/// `truth/imu_state.txt`: the true state of the IMU at every IMU sample, which
/// no real dataset has. One line per sample, 23 columns:
///   t  px py pz  qx qy qz qw  vx vy vz  wx wy wz  ax ay az  bax bay baz  bgx bgy bgz
/// t in seconds (true time); p_W_B in m; q_W_B Hamilton x y z w; v_W in m/s;
/// ω_B (angular velocity of B in B) in rad/s; a_W (acceleration of B in W,
/// gravity not included) in m/s²; accelerometer bias in m/s² and gyroscope
/// bias in rad/s (the biases inside that sample).

#include <string>
#include <vector>

#include "evio/core/io/timed_table.h"
#include "evio/core/pose.h"

namespace evio::io {

/// One row of truth/imu_state.txt.
struct ImuTruthState {
  TimeNs t_ns = 0;
  Pose T_W_B;
  Vec3 v_W = Vec3::Zero();
  Vec3 omega_B = Vec3::Zero();
  Vec3 a_W = Vec3::Zero();
  Vec3 accel_bias = Vec3::Zero();
  Vec3 gyro_bias = Vec3::Zero();

  bool operator==(const ImuTruthState& o) const;
};

/// Streams rows; validates the 23 columns, finite numbers, strictly
/// increasing time and unit quaternions (within 1 %, then normalised).
class ImuStateReader {
 public:
  explicit ImuStateReader(std::string path);
  bool next(ImuTruthState& state);

 private:
  TimedTableReader table_;
};

std::vector<ImuTruthState> readImuStateText(const std::string& path);

/// Streams rows into the file, atomically on close(). Doubles are written in
/// shortest round-trip form, so reading back gives the same bits.
class ImuStateWriter {
 public:
  explicit ImuStateWriter(std::string path, const std::vector<std::string>& header = {});
  void append(const ImuTruthState& state);
  void close();

 private:
  TimedTableWriter table_;
};

void writeImuStateText(const std::string& path, const std::vector<ImuTruthState>& states,
                       const std::vector<std::string>& header = {});

}  // namespace evio::io

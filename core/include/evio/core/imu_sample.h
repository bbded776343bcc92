#pragma once
/// @file imu_sample.h

#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/time.h"

namespace evio {

/// One IMU reading in the IMU (body) frame B.
struct ImuSample {
  TimeNs t_ns = 0;
  Vec3 acc_B = Vec3::Zero();   ///< specific force a_B = R_B_W (a_W - g_W), m/s^2
  Vec3 gyro_B = Vec3::Zero();  ///< angular rate of B w.r.t. W, expressed in B, rad/s

  bool operator==(const ImuSample& o) const {
    return t_ns == o.t_ns && acc_B == o.acc_B && gyro_B == o.gyro_B;
  }
};

using ImuSamples = std::vector<ImuSample>;

}  // namespace evio

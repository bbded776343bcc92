#include "evio/estimator/backend/static_initializer.h"

#include <cmath>

namespace evio::estimator {

std::optional<StaticInitResult> staticInitialize(const ImuSamples& samples, double gravity_mps2,
                                                 double max_acc_std_mps2, double max_gyro_std_radps,
                                                 const Vec3& p_W_B, double yaw_rad) {
  if (samples.size() < 2) return std::nullopt;
  Vec3 acc_mean = Vec3::Zero(), gyro_mean = Vec3::Zero();
  for (const ImuSample& s : samples) {
    acc_mean += s.acc_B;
    gyro_mean += s.gyro_B;
  }
  const double n = static_cast<double>(samples.size());
  acc_mean /= n;
  gyro_mean /= n;
  Vec3 acc_var = Vec3::Zero(), gyro_var = Vec3::Zero();
  for (const ImuSample& s : samples) {
    acc_var += (s.acc_B - acc_mean).cwiseAbs2();
    gyro_var += (s.gyro_B - gyro_mean).cwiseAbs2();
  }
  StaticInitResult out;
  out.acc_std = (acc_var / (n - 1.0)).cwiseSqrt();
  out.gyro_std = (gyro_var / (n - 1.0)).cwiseSqrt();
  if (!acc_mean.allFinite() || !gyro_mean.allFinite()) return std::nullopt;
  if (out.acc_std.maxCoeff() > max_acc_std_mps2 || out.gyro_std.maxCoeff() > max_gyro_std_radps)
    return std::nullopt;
  if (std::abs(acc_mean.norm() - gravity_mps2) > 0.2 * gravity_mps2) return std::nullopt;

  // Rotation taking the measured "up" (ā in B) onto e_z of W, then yaw removed and set.
  const Quat q_tilt = Quat::FromTwoVectors(acc_mean.normalized(), Vec3::UnitZ());
  const Mat3 R = q_tilt.toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0));  // ZYX yaw of R
  const Mat3 R_W_B = Eigen::AngleAxisd(yaw_rad - yaw, Vec3::UnitZ()).toRotationMatrix() * R;

  out.state.t_ns = samples.back().t_ns;
  out.state.p_W_B = p_W_B;
  out.state.v_W.setZero();
  out.state.q_W_B = Quat(R_W_B).normalized();
  out.state.b_g = gyro_mean;
  out.state.b_a.setZero();
  return out;
}

}  // namespace evio::estimator

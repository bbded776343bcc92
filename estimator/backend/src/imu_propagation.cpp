#include "evio/estimator/backend/imu_propagation.h"

#include "evio/core/so3.h"

namespace evio::estimator {

ImuSample interpolateImu(const ImuSample& s0, const ImuSample& s1, TimeNs t_ns) {
  const double w = static_cast<double>(t_ns - s0.t_ns) / static_cast<double>(s1.t_ns - s0.t_ns);
  ImuSample s;
  s.t_ns = t_ns;
  s.acc_B = (1.0 - w) * s0.acc_B + w * s1.acc_B;
  s.gyro_B = (1.0 - w) * s0.gyro_B + w * s1.gyro_B;
  return s;
}

void integrateImuStep(ImuState& x, const ImuSample& s0, const ImuSample& s1, const Vec3& g_W, Mat15* Phi) {
  const double dt = nsToSeconds(s1.t_ns - s0.t_ns);
  const Vec3 w0 = s0.gyro_B - x.b_g, w1 = s1.gyro_B - x.b_g;
  const Vec3 a0 = s0.acc_B - x.b_a, a1 = s1.acc_B - x.b_a;
  const Vec3 theta = 0.5 * (w0 + w1) * dt + (dt * dt / 12.0) * w0.cross(w1);
  const Mat3 R0 = x.q_W_B.toRotationMatrix();
  const Quat q1 = (x.q_W_B * so3::expQuat(theta)).normalized();
  const Mat3 R1 = q1.toRotationMatrix();
  const Vec3 aW0 = R0 * a0 + g_W;
  const Vec3 aW1 = R1 * a1 + g_W;

  if (Phi != nullptr) {
    const Mat3 I = Mat3::Identity();
    const Mat3 A0 = R0 * so3::hat(a0), A1 = R1 * so3::hat(a1);
    const Mat3 F_tt = so3::exp(-theta);
    // ∂θ/∂b_g = −(Δt I − (Δt²/12) [ω_1 − ω_0]x)  (the Magnus term depends on b_g too).
    const Mat3 F_tg = -so3::rightJacobian(theta) * (I * dt - (dt * dt / 12.0) * so3::hat(w1 - w0));
    Mat15& F = *Phi;
    F.setIdentity();
    F.block<3, 3>(kIdxP, kIdxV) = I * dt;
    F.block<3, 3>(kIdxP, kIdxTheta) = -(A0 / 3.0 + A1 * F_tt / 6.0) * dt * dt;
    F.block<3, 3>(kIdxP, kIdxBg) = -(A1 * F_tg / 6.0) * dt * dt;
    F.block<3, 3>(kIdxP, kIdxBa) = -(R0 / 3.0 + R1 / 6.0) * dt * dt;
    F.block<3, 3>(kIdxV, kIdxTheta) = -(A0 + A1 * F_tt) * (0.5 * dt);
    F.block<3, 3>(kIdxV, kIdxBg) = -A1 * F_tg * (0.5 * dt);
    F.block<3, 3>(kIdxV, kIdxBa) = -(R0 + R1) * (0.5 * dt);
    F.block<3, 3>(kIdxTheta, kIdxTheta) = F_tt;
    F.block<3, 3>(kIdxTheta, kIdxBg) = F_tg;
  }

  x.p_W_B += x.v_W * dt + (aW0 / 3.0 + aW1 / 6.0) * dt * dt;
  x.v_W += 0.5 * (aW0 + aW1) * dt;
  x.q_W_B = q1;
  x.t_ns = s1.t_ns;
}

Mat15 discreteImuNoise(const Mat3& R, const Vec3& a_B, double dt, const ImuNoiseDensities& n) {
  const double sa = n.accelerometer_noise_density * n.accelerometer_noise_density;
  const double sba = n.accelerometer_random_walk * n.accelerometer_random_walk;
  const double sg = n.gyroscope_noise_density * n.gyroscope_noise_density;
  const double sbg = n.gyroscope_random_walk * n.gyroscope_random_walk;
  const Mat3 I = Mat3::Identity();
  const Mat3 A = R * so3::hat(a_B);
  const Mat3 AA = A * A.transpose();
  const double d1 = dt, d2 = dt * dt, d3 = d2 * dt, d4 = d3 * dt, d5 = d4 * dt, d6 = d5 * dt, d7 = d6 * dt;

  Mat15 Q = Mat15::Zero();
  auto blk = [&Q](int r, int c) { return Q.block<3, 3>(r, c); };
  // Upper-triangular blocks (row block <= column block in p v θ g a order).
  blk(kIdxP, kIdxP) = sg * AA * d5 / 20.0 + sa * I * d3 / 3.0 + sbg * AA * d7 / 252.0 + sba * I * d5 / 20.0;
  blk(kIdxP, kIdxV) = sg * AA * d4 / 8.0 + sa * I * d2 / 2.0 + sbg * AA * d6 / 72.0 + sba * I * d4 / 8.0;
  blk(kIdxP, kIdxTheta) = -sg * A * d3 / 6.0 - sbg * A * d5 / 30.0;
  blk(kIdxP, kIdxBg) = sbg * A * d4 / 24.0;
  blk(kIdxP, kIdxBa) = -sba * R * d3 / 6.0;
  blk(kIdxV, kIdxV) = sg * AA * d3 / 3.0 + sa * I * d1 + sbg * AA * d5 / 20.0 + sba * I * d3 / 3.0;
  blk(kIdxV, kIdxTheta) = -sg * A * d2 / 2.0 - sbg * A * d4 / 8.0;
  blk(kIdxV, kIdxBg) = sbg * A * d3 / 6.0;
  blk(kIdxV, kIdxBa) = -sba * R * d2 / 2.0;
  blk(kIdxTheta, kIdxTheta) = sg * I * d1 + sbg * I * d3 / 3.0;
  blk(kIdxTheta, kIdxBg) = -sbg * I * d2 / 2.0;
  blk(kIdxBg, kIdxBg) = sbg * I * d1;
  blk(kIdxBa, kIdxBa) = sba * I * d1;
  // Lower triangle by symmetry.
  for (int r = 0; r < 15; r += 3)
    for (int c = r + 3; c < 15; c += 3) Q.block<3, 3>(c, r) = Q.block<3, 3>(r, c).transpose();
  return Q;
}

}  // namespace evio::estimator

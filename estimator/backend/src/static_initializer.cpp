#include "evio/estimator/backend/static_initializer.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Cholesky>

#include "evio/core/so3.h"

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

double medianRateHz(const ImuSamples& samples) {
  if (samples.size() < 2) return 0.0;
  std::vector<TimeNs> spacing;
  spacing.reserve(samples.size() - 1);
  for (std::size_t i = 1; i < samples.size(); ++i) spacing.push_back(samples[i].t_ns - samples[i - 1].t_ns);
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(spacing.size() / 2), spacing.end());
  const double median_dt = nsToSeconds(spacing[spacing.size() / 2]);
  return median_dt > 0.0 ? 1.0 / median_dt : 0.0;
}

std::optional<RestMeasurement> restMeasurement(const ImuSamples& samples, double gravity_mps2, double max_acc_std_mps2,
                                               double max_gyro_std_radps, const ImuNoiseDensities& noise) {
  if (samples.size() < 2) return std::nullopt;
  RestMeasurement m;
  m.t0_ns = samples.front().t_ns;
  m.t1_ns = samples.back().t_ns;
  const double T = m.durationS();
  if (!(T > 0.0)) return std::nullopt;
  // The bounds are the spread motion may add: the white noise's own spread
  // per reading, σ √f at f readings per second, is added in quadrature, so
  // that a still IMU passes at any rate (1 kHz: 0.14 m/s², 0.006 rad/s at
  // the DAVIS240's densities).
  // f: the sensor's rate from the median spacing, so that a gap in the
  // readings does not pass for a slower sensor (the variance of a mean of N
  // readings is σ² f / N, not σ²/T, when some are missing).
  const double f = medianRateHz(samples);
  if (!(f > 0.0)) return std::nullopt;
  const auto bound = [f](double motion, double density) { return std::sqrt(motion * motion + density * density * f); };
  const std::optional<StaticInitResult> still =
      staticInitialize(samples, gravity_mps2, bound(max_acc_std_mps2, noise.accelerometer_noise_density),
                       bound(max_gyro_std_radps, noise.gyroscope_noise_density));
  if (!still) return std::nullopt;
  for (const ImuSample& s : samples) m.mean_acc += s.acc_B;
  m.mean_acc /= static_cast<double>(samples.size());
  m.mean_gyro = still->state.b_g;
  const double n = static_cast<double>(samples.size());
  const auto variance = [T, f, n](double density, double random_walk) {
    return density * density * f / n + random_walk * random_walk * T / 3.0;
  };
  m.gyro_variance = variance(noise.gyroscope_noise_density, noise.gyroscope_random_walk);
  m.acc_variance = variance(noise.accelerometer_noise_density, noise.accelerometer_random_walk);
  return m;
}

namespace {

/// The covariance of the force's second-order term in the attitude error e,
/// Exp(−e) f ≈ f − e × f + q(e) with q(e) = ½ e × (e × f): a tilt lowers
/// the force along itself by g |e⊥|²/2, and a yaw error turns the tilt's
/// term sideways, by g ψ θ. No linearisation carries either; with the
/// prior's σ of 3° they reach 0.03 m/s², seven times a second's mean noise.
/// q_k = ½ eᵀ B_k e with B_k = ½ (u_k fᵀ + f u_kᵀ) − f_k I (u_k the k-th
/// axis), and for e ~ N(0, P_θ): E[q_k] = ½ tr(B_k P_θ) (along the force
/// −g σ⊥², σ⊥² the tilt variance summed over both axes) and, by Isserlis,
/// Cov(q_k, q_l) = ½ tr(B_k P_θ B_l P_θ).
struct SecondOrderForce {
  Vec3 mean = Vec3::Zero();  ///< E[q] = ½ tr(B_k P_θ) per axis
  Mat3 covariance = Mat3::Zero();
};

SecondOrderForce secondOrderForce(const ImuState& x, const Mat3& P_theta, double gravity_mps2) {
  const Vec3 f = x.q_W_B.toRotationMatrix().transpose() * Vec3(0.0, 0.0, gravity_mps2);
  Mat3 BP[3];
  SecondOrderForce out;
  for (int k = 0; k < 3; ++k) {
    const Vec3 u = Vec3::Unit(k);
    const Mat3 B = 0.5 * (u * f.transpose() + f * u.transpose()) - f(k) * Mat3::Identity();
    BP[k] = B * P_theta;
    out.mean(k) = 0.5 * BP[k].trace();
  }
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) out.covariance(k, l) = 0.5 * (BP[k] * BP[l]).trace();
  return out;
}

/// A filter state of the IMU alone: its correct() and minus() are the
/// filter's ⊞ and ⊟ (filter_state.cpp), so the update here retracts and
/// compares states exactly as the filter does.
FilterState imuOnly(const ImuState& x) {
  FilterState s;
  s.imu = x;
  return s;
}

}  // namespace

namespace {

using Matrix15 = Eigen::Matrix<double, 15, 15>;

/// χ²₆ at 0.999: the rest measurement's innovation against the prior.
constexpr double kRestGateChi2 = 22.458;

/// The iterated update of (x, P) by the rest measurement with noise R.
/// Iterated because the force is quadratic in the attitude error (its
/// vertical part falls by g θ²/2, 0.013 m/s² at 3°, three times the noise of
/// a second's mean): Gauss–Newton on prior plus measurement, relinearised at
/// each iterate until the step is below 1e-12; then the Joseph form at the
/// last linearisation (the prior is wide, the rest tight: it keeps P
/// symmetric and positive semi-definite).
bool iteratedRestUpdate(const RestMeasurement& rest, double gravity_mps2, const SecondOrderForce& q,
                        const Eigen::Matrix<double, 6, 6>& R0, ImuState* x, Matrix15* P) {
  Eigen::Matrix<double, 6, 6> R = R0;
  R.block<3, 3>(3, 3) += q.covariance;
  const FilterState x0 = imuOnly(*x);
  FilterState xi = x0;
  Eigen::Matrix<double, 6, 15> H;
  Eigen::Matrix<double, 15, 6> K;
  for (int it = 0; it < 10; ++it) {
    const Vec3 f_B = xi.imu.q_W_B.toRotationMatrix().transpose() * Vec3(0.0, 0.0, gravity_mps2);  // force at rest
    H.setZero();
    H.block<3, 3>(0, kIdxBg).setIdentity();
    H.block<3, 3>(3, kIdxTheta) = so3::hat(f_B);
    H.block<3, 3>(3, kIdxBa).setIdentity();
    Eigen::Matrix<double, 6, 1> r;
    r.head<3>() = rest.mean_gyro - xi.imu.b_g;
    r.tail<3>() = rest.mean_acc - (f_B + xi.imu.b_a + q.mean);
    const Eigen::Matrix<double, 15, 1> di = xi.minus(x0);
    const Eigen::Matrix<double, 15, 6> PHt = *P * H.transpose();
    const Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(H * PHt + R);
    if (llt.info() != Eigen::Success) return false;
    // The rest hypothesis is tested against the prior at the first
    // linearisation: a body turning at a steady rate or accelerating
    // smoothly passes the spread test, and its mean would be taken as bias.
    if (it == 0 && r.dot(llt.solve(r)) > kRestGateChi2) return false;
    K = llt.solve(PHt.transpose()).transpose();
    const Eigen::Matrix<double, 15, 1> dx = K * (r + H * di);
    const double step = (dx - di).norm();
    xi = x0;
    xi.correct(dx);
    if (step < 1e-12) break;
  }
  const Matrix15 IKH = Matrix15::Identity() - K * H;
  const Matrix15 Pn = IKH * *P * IKH.transpose() + K * R * K.transpose();
  *P = 0.5 * (Pn + Pn.transpose());
  *x = xi.imu;
  return true;
}

}  // namespace

bool applyRestMeasurement(const RestMeasurement& rest, double gravity_mps2, ImuState* x, Matrix15* P) {
  Eigen::Matrix<double, 6, 6> R = Eigen::Matrix<double, 6, 6>::Zero();
  R.diagonal().head<3>().setConstant(rest.gyro_variance);
  R.diagonal().tail<3>().setConstant(rest.acc_variance);
  // The second-order term's spread is set by the attitude error that is left
  // at the solution: a first update with the prior's, then the update again
  // from the prior with the attitude covariance that one left.
  ImuState x1 = *x;
  Matrix15 P1 = *P;
  const SecondOrderForce q1 = secondOrderForce(*x, P->block<3, 3>(kIdxTheta, kIdxTheta), gravity_mps2);
  if (!iteratedRestUpdate(rest, gravity_mps2, q1, R, &x1, &P1)) return false;
  const SecondOrderForce q2 = secondOrderForce(x1, P1.block<3, 3>(kIdxTheta, kIdxTheta), gravity_mps2);
  ImuState x2 = *x;
  Matrix15 P2 = *P;
  if (!iteratedRestUpdate(rest, gravity_mps2, q2, R, &x2, &P2)) return false;
  *x = x2;
  *P = P2;
  return true;
}

}  // namespace evio::estimator

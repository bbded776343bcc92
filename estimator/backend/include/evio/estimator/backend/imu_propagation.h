#pragma once
/// @file imu_propagation.h
/// IMU propagation of the backend (docs/algorithms.md#imu-propagation: higher-order
/// quaternion integration on the mean rate, trapezoidal velocity/position,
/// closed-form discrete transition and noise). Error-state convention:
/// filter_state.h (R = R̂ Exp(δθ), δθ in B).
///
/// One step from reading k (time t0) to reading k+1 (t1 = t0 + Δt), with the
/// bias estimates removed, ω_i = gyro_i − b_g, a_i = acc_i − b_a:
///
///   θ      = ½(ω_0 + ω_1) Δt + (Δt²/12) ω_0 × ω_1     (2nd-order Magnus term of a linearly varying rate)
///   R_1    = R_0 Exp(θ)
///   a_W,i  = R_i a_i + g_W,  g_W = (0, 0, −g)
///   v_1    = v_0 + ½ (a_W,0 + a_W,1) Δt
///   p_1    = p_0 + v_0 Δt + (a_W,0/3 + a_W,1/6) Δt²      (exact for a linearly varying a_W)
///
/// The transition Φ (15×15, error order p v θ b_g b_a) is the exact Jacobian of
/// this discrete map (with A_i = R_i [a_i]x, Φ_θθ = Exp(θ)ᵀ,
/// Φ_θg = −Jr(θ) (Δt I − (Δt²/12) [ω_1 − ω_0]x)):
///
///   Φ_pv = I Δt,  Φ_pθ = −(A_0/3 + A_1 Φ_θθ/6) Δt²,  Φ_pg = −(A_1 Φ_θg/6) Δt²,  Φ_pa = −(R_0/3 + R_1/6) Δt²
///   Φ_vθ = −(A_0 + A_1 Φ_θθ) Δt/2,  Φ_vg = −A_1 Φ_θg Δt/2,  Φ_va = −(R_0 + R_1) Δt/2
///
/// The discrete noise Q_d is ∫₀^Δt g(u) Q_c g(u)ᵀ du in closed form, with the
/// rotation R = R_0 and A = R_0[a_0]x held over the step, u = Δt − s the time
/// left after a noise impulse at s, and the impulse responses
///   n_g  (σ_g²):   δθ = −I,     δv = A u,        δp = A u²/2
///   n_a  (σ_a²):                δv = −R,         δp = −R u
///   n_bg (σ_bg²):  δb_g = I,    δθ = −I u,  δv = A u²/2,  δp = A u³/6
///   n_ba (σ_ba²):  δb_a = I,    δv = −R u,  δp = −R u²/2
/// (σ the continuous densities of sensors.yaml, Kalibr's names).

#include "evio/core/eigen_types.h"
#include "evio/core/imu_sample.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

using Mat15 = Eigen::Matrix<double, 15, 15>;

/// Continuous-time IMU noise densities (Kalibr's names and units).
struct ImuNoiseDensities {
  double accelerometer_noise_density = 0.0;  ///< σ_a, m/s²/√Hz
  double accelerometer_random_walk = 0.0;    ///< σ_ba, m/s³/√Hz
  double gyroscope_noise_density = 0.0;      ///< σ_g, rad/s/√Hz
  double gyroscope_random_walk = 0.0;        ///< σ_bg, rad/s²/√Hz
};

/// The reading at time t on the straight line between s0 and s1 (t0 <= t <= t1, t0 < t1).
ImuSample interpolateImu(const ImuSample& s0, const ImuSample& s1, TimeNs t_ns);

/// Propagates the mean of `state` from s0.t_ns to s1.t_ns (state.t_ns is set to
/// s1.t_ns) and optionally returns the transition Φ of the step (see file comment).
/// `g_W` is the gravity vector in W (0, 0, −g).
void integrateImuStep(ImuState& state, const ImuSample& s0, const ImuSample& s1, const Vec3& g_W,
                      Mat15* Phi = nullptr);

/// Closed-form discrete noise of a step of length dt_s starting with attitude R_W_B
/// and bias-corrected specific force a_B (see file comment).
Mat15 discreteImuNoise(const Mat3& R_W_B, const Vec3& a_B, double dt_s, const ImuNoiseDensities& noise);

}  // namespace evio::estimator

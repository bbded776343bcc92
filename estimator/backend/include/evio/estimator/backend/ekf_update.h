#pragma once
/// @file ekf_update.h
/// Small static helpers of the EKF update (OpenVINS/xVIO style). All
/// measurement noise here is isotropic, R = σ² I, which orthonormal
/// projections (null space, QR compression) preserve.

#include "evio/core/eigen_types.h"
#include "evio/estimator/backend/filter_state.h"

namespace evio::estimator {

/// Left-null-space projection (MSCKF, Mourikis & Roumeliotis 2007): with the
/// QR factorisation H_f = [Q1 Q2] [R1; 0] (H_f: m×k, full column rank, m > k),
/// replaces H_x by Q2ᵀ H_x and r by Q2ᵀ r (m−k rows), so that the residual
/// r_o = Q2ᵀ r no longer depends on the feature error: Q2ᵀ H_f = 0.
/// Returns Q2 through `null_space` when non-null.
void projectOnLeftNullSpace(const MatX& H_f, MatX* H_x, VecX* r, MatX* null_space = nullptr);

/// QR compression of a stacked update with more rows than columns:
/// H = [Q1 Q2][T; 0] ⇒ (H, r) ← (T, Q1ᵀ r), rows = rank bound min(m, n).
/// Leaves (H, r) unchanged when m <= n.
void compressMeasurement(MatX* H, VecX* r);

/// Squared Mahalanobis distance of residual r: rᵀ (H P Hᵀ + σ² I)⁻¹ r.
/// Returns +inf when the innovation covariance is not positive definite.
double mahalanobisSquared(const MatX& H, const VecX& r, const MatX& P, double sigma2);

/// EKF update with R = σ² I:  S = H P Hᵀ + R,  K = P Hᵀ S⁻¹,  δx = K r,
/// P ← (I − K H) P (I − K H)ᵀ + K R Kᵀ  (Joseph form, when joseph) or
/// P ← P − K S Kᵀ, then symmetrised; the mean is corrected by δx.
/// covariance_factor κ ≥ 1: the gain keeps R = σ² I but the covariance takes
/// the rows' noise as κ σ² I, P ← (I − K H) P (I − K H)ᵀ + κ σ² K Kᵀ: the
/// covariance of this update's estimate when the real noise is κ σ²
/// (κ = 1: the optimal update).
/// Returns false (state unchanged) when S is not positive definite.
bool ekfUpdate(FilterState& state, const MatX& H, const VecX& r, double sigma2, bool joseph,
               double covariance_factor = 1.0);

/// Iterated EKF update (Bell & Cathey 1993; xVIO's iekf_iter) for a stacked
/// measurement whose first part is re-linearised at every iterate and whose
/// second part (H_fixed, r_fixed) is linear in the error state:
///   x_{i+1} = x_0 ⊞ K_i (r_i + H_i (x_i ⊟ x_0)),   K_i = P H_iᵀ (H_i P H_iᵀ + σ² I)⁻¹,
/// with (H_i, r_i) = relinearize(x_i) stacked over (H_fixed, r_fixed) and QR
/// compressed; P is updated once with the last K_i, H_i (Joseph form when
/// joseph; its noise taken as covariance_factor σ², see ekfUpdate).
/// iterations = 1 is the EKF update. Stops early when the step changes by
/// less than 1e-9 in norm. Returns false (state unchanged) when an
/// innovation covariance is not positive definite.
/// relinearize(const FilterState& x, MatX* H, VecX* r) must always give the
/// same rows (same measurements) in the same order.
template <class Relinearize>
bool iteratedEkfUpdate(FilterState& state, Relinearize&& relinearize, const MatX& H_fixed, const VecX& r_fixed,
                       double sigma2, int iterations, bool joseph, double covariance_factor = 1.0) {
  const FilterState prior = state;
  FilterState x = state;
  VecX dx_prev;
  MatX H;
  VecX r;
  for (int it = 0; it < iterations; ++it) {
    MatX H_lin;
    VecX r_lin;
    relinearize(x, &H_lin, &r_lin);
    const Eigen::Index m1 = H_lin.rows(), m2 = H_fixed.rows();
    H.resize(m1 + m2, prior.dim());
    r.resize(m1 + m2);
    if (m1 > 0) {
      H.topRows(m1) = H_lin;
      r.head(m1) = r_lin + H_lin * x.minus(prior);
    }
    if (m2 > 0) {
      H.bottomRows(m2) = H_fixed;
      r.tail(m2) = r_fixed;
    }
    if (H.rows() == 0) return true;
    compressMeasurement(&H, &r);
    FilterState trial = prior;
    if (!ekfUpdate(trial, H, r, sigma2, joseph, covariance_factor)) return false;
    const VecX dx = trial.minus(prior);
    x = std::move(trial);
    if (it > 0 && (dx - dx_prev).norm() < 1e-9) break;
    dx_prev = dx;
  }
  state = std::move(x);
  return true;
}

}  // namespace evio::estimator

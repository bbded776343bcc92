#include "evio/estimator/backend/ekf_update.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <limits>

#include "evio/core/error.h"

namespace evio::estimator {

void projectOnLeftNullSpace(const MatX& H_f, MatX* H_x, VecX* r, MatX* null_space) {
  const Eigen::Index m = H_f.rows(), k = H_f.cols();
  require(m > k && H_x->rows() == m && r->size() == m, "projectOnLeftNullSpace: inconsistent sizes");
  const Eigen::HouseholderQR<MatX> qr(H_f);
  // Qᵀ applied in place: the last m − k rows span the left null space.
  MatX QtH = qr.householderQ().adjoint() * (*H_x);
  VecX Qtr = qr.householderQ().adjoint() * (*r);
  *H_x = QtH.bottomRows(m - k);
  *r = Qtr.tail(m - k);
  if (null_space != nullptr) {
    const MatX Q = qr.householderQ() * MatX::Identity(m, m);
    *null_space = Q.rightCols(m - k);
  }
}

void compressMeasurement(MatX* H, VecX* r) {
  const Eigen::Index m = H->rows(), n = H->cols();
  if (m <= n) return;
  const Eigen::HouseholderQR<MatX> qr(*H);
  const VecX Qtr = qr.householderQ().adjoint() * (*r);
  MatX T = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  *H = std::move(T);
  *r = Qtr.head(n);
}

double mahalanobisSquared(const MatX& H, const VecX& r, const MatX& P, double sigma2) {
  MatX S = H * P * H.transpose();
  S.diagonal().array() += sigma2;
  const Eigen::LLT<MatX> llt(S);
  if (llt.info() != Eigen::Success) return std::numeric_limits<double>::infinity();
  return r.dot(llt.solve(r));
}

bool ekfUpdate(FilterState& state, const MatX& H, const VecX& r, double sigma2, bool joseph,
               double covariance_factor) {
  const MatX& P = state.P;
  const MatX PHt = P * H.transpose();
  MatX S = H * PHt;
  S.diagonal().array() += sigma2;
  S = 0.5 * (S + S.transpose()).eval();
  const Eigen::LLT<MatX> llt(S);
  if (llt.info() != Eigen::Success) return false;
  const MatX K = llt.solve(PHt.transpose()).transpose();  // P Hᵀ S⁻¹
  const VecX dx = K * r;
  if (!dx.allFinite()) return false;
  if (joseph) {
    // Joseph form (I − KH) P (I − KH)ᵀ + σ² K Kᵀ without an n × n by n × n product:
    // A = (I − KH) P = P − K (P Hᵀ)ᵀ, then A (I − KH)ᵀ = A − (A Hᵀ) Kᵀ;
    // every product is (n × m)(m × n) or (n × n)(n × m): O(n² m), not O(n³).
    MatX A = P;
    A.noalias() -= K * PHt.transpose();
    const MatX AHt = A * H.transpose();
    MatX Pn = std::move(A);
    Pn.noalias() -= AHt * K.transpose();
    Pn.noalias() += covariance_factor * sigma2 * K * K.transpose();
    state.P.swap(Pn);
  } else {
    // With the optimal gain the Joseph form is P − K S Kᵀ; its noise term
    // σ² K Kᵀ becomes κ σ² K Kᵀ, so κ adds (κ − 1) σ² K Kᵀ.
    state.P.noalias() -= K * S * K.transpose();
    if (covariance_factor != 1.0) state.P.noalias() += (covariance_factor - 1.0) * sigma2 * K * K.transpose();
  }
  state.symmetrize();
  state.correct(dx);
  return true;
}

}  // namespace evio::estimator

#include "evio/estimator/backend/triangulation.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>

#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

namespace {
/// √[(JᵀJ)⁻¹]_ρρ, the σ of ρ per unit observation noise; infinity when JᵀJ
/// is singular (no baseline). [(JᵀJ)⁻¹]_ρρ = 1 / (Schur complement of the
/// bearing block), which stays finite where the full inverse would not.
double inverseDepthSigma(const Mat3& JtJ) {
  const Eigen::Matrix2d A = JtJ.topLeftCorner<2, 2>();
  const Eigen::Vector2d b = JtJ.topRightCorner<2, 1>();
  const Eigen::LDLT<Eigen::Matrix2d> ldlt(A);
  if (ldlt.info() != Eigen::Success || !(A.determinant() > 0.0)) return std::numeric_limits<double>::infinity();
  const double schur = JtJ(2, 2) - b.dot(ldlt.solve(b));
  return schur > 0.0 ? 1.0 / std::sqrt(schur) : std::numeric_limits<double>::infinity();
}

/// The reprojection residuals z_i − π(h_i(x)) of a track anchored in
/// clones[anchor], whitened by (*whiten)[i] when whiten is given, into the
/// first 2n rows of r, and their Jacobians ∂ẑ/∂x into the first 2n rows of J
/// when J is given. False when the point is behind a clone.
bool trackResiduals(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                    const std::vector<Mat2>* whiten, std::size_t anchor, const Vec3& x, Eigen::VectorXd* r,
                    Eigen::MatrixXd* J) {
  for (std::size_t i = 0; i < clones.size(); ++i) {
    Vec2 zi;
    Mat23 Ji;
    if (!projectAnchoredFeature(clones[anchor], clones[i], x, &zi, nullptr, nullptr, J != nullptr ? &Ji : nullptr))
      return false;
    const auto row = 2 * static_cast<Eigen::Index>(i);
    if (whiten == nullptr) {
      r->segment<2>(row) = z[i] - zi;
      if (J != nullptr) J->block<2, 3>(row, 0) = Ji;
    } else {
      r->segment<2>(row) = (*whiten)[i] * (z[i] - zi);
      if (J != nullptr) J->block<2, 3>(row, 0) = (*whiten)[i] * Ji;
    }
  }
  return true;
}

}  // namespace

bool triangulateFeature(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z, std::size_t anchor,
                        const TriangulationOptions& options, TriangulationResult* result) {
  const std::size_t n = clones.size();
  if (n < 2 || z.size() != n || anchor >= n) return false;

  // 1. Linear start.
  Mat3 A = Mat3::Zero();
  Vec3 rhs = Vec3::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 b = (clones[i].R_W_C() * Vec3(z[i].x(), z[i].y(), 1.0)).normalized();
    const Mat3 M = Mat3::Identity() - b * b.transpose();
    A += M;
    rhs += M * clones[i].p_W_C;
  }
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(A);
  const Vec3 ev = eig.eigenvalues();
  if (!(ev(0) > 1e-12 * ev(2))) return false;
  const Vec3 p0 = A.ldlt().solve(rhs);
  Vec3 abr;
  if (!worldToAnchored(clones[anchor], p0, &abr)) return false;

  // 2. Gauss–Newton in inverse depth.
  Eigen::MatrixXd J(2 * n, 3);
  Eigen::VectorXd r(2 * n);
  auto evaluate = [&](const Vec3& x, bool jac) {
    return trackResiduals(clones, z, nullptr, anchor, x, &r, jac ? &J : nullptr);
  };
  int it = 0;
  for (; it < options.max_iterations; ++it) {
    if (!evaluate(abr, true)) return false;
    const Mat3 JtJ = J.transpose() * J;
    const Vec3 step = JtJ.ldlt().solve(J.transpose() * r);
    if (!step.allFinite()) return false;
    abr += step;
    if (step.norm() <= options.tolerance * abr.norm()) {
      ++it;
      break;
    }
  }
  if (!evaluate(abr, true)) return false;
  const double rho = abr.z();
  if (!(rho > 0.0) || 1.0 / rho > options.max_depth_m) return false;
  const Vec3 p_W = anchoredToWorld(clones[anchor], abr);
  for (const CameraClone& c : clones) {
    const double depth = (c.R_W_C().transpose() * (p_W - c.p_W_C)).z();
    if (!(depth >= options.min_depth_m)) return false;
  }
  result->abr = abr;
  result->p_W = p_W;
  result->iterations = it;
  result->rms_residual = std::sqrt(r.squaredNorm() / static_cast<double>(n));
  result->sigma_rho_unit = inverseDepthSigma(J.transpose() * J);
  if (options.max_rms_residual > 0.0 && result->rms_residual > options.max_rms_residual) return false;
  return true;
}

bool refineWithDepthPrior(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                          const std::vector<Mat2>& whiten, std::size_t anchor, double rho0, double sigma_rho0,
                          double sigma_z, const TriangulationOptions& options, Vec3* abr) {
  const std::size_t n = clones.size();
  if (n < 1 || z.size() != n || whiten.size() != n || anchor >= n || !(sigma_rho0 > 0.0) || !(sigma_z > 0.0))
    return false;
  const double w_prior = sigma_z / sigma_rho0;  // the prior row whitened to σ_z
  const auto rows = static_cast<Eigen::Index>(2 * n + 1);
  Eigen::MatrixXd J(rows, 3);
  Eigen::VectorXd r(rows);
  // Residuals (and Jacobians ∂ẑ/∂x, the GN convention of triangulateFeature) at x.
  auto evaluate = [&](const Vec3& x, bool jac) {
    if (!trackResiduals(clones, z, &whiten, anchor, x, &r, jac ? &J : nullptr)) return false;
    r(rows - 1) = w_prior * (rho0 - x.z());
    if (jac) J.row(rows - 1) = Eigen::RowVector3d(0.0, 0.0, w_prior);
    return true;
  };
  Vec3 x(z[anchor].x(), z[anchor].y(), rho0);
  if (!evaluate(x, true)) return false;
  double cost = r.squaredNorm();
  for (int it = 0; it < options.max_iterations; ++it) {
    const Mat3 JtJ = J.transpose() * J;
    Vec3 step = JtJ.ldlt().solve(J.transpose() * r);
    if (!step.allFinite()) return false;
    double scale = 1.0;
    bool fell = false;
    for (int halving = 0; halving <= 10; ++halving, scale *= 0.5) {
      const Vec3 trial = x + scale * step;
      if (trial.z() > 0.0 && evaluate(trial, false) && r.squaredNorm() <= cost) {
        x = trial;
        cost = r.squaredNorm();
        fell = true;
        break;
      }
    }
    if (!fell) break;  // no step lowers the cost: x is the minimum found
    if (!evaluate(x, true)) return false;
    if (scale * step.norm() <= options.tolerance * x.norm()) break;
  }
  if (!(x.z() > 0.0)) return false;
  const Vec3 p_W = anchoredToWorld(clones[anchor], x);
  for (const CameraClone& c : clones)
    if (!((c.R_W_C().transpose() * (p_W - c.p_W_C)).z() >= options.min_depth_m)) return false;
  *abr = x;
  return true;
}

bool knowsDepth(const TriangulationResult& result, const TriangulationOptions& options) {
  return !(options.max_sigma_rho > 0.0) || options.sigma_z * result.sigma_rho_unit <= options.max_sigma_rho;
}

double rotationCompensatedDisparity(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z) {
  if (clones.size() < 2) return 0.0;
  const Mat3 Rlt = clones.back().R_W_C().transpose();
  double best = 0.0;
  for (std::size_t i = 0; i + 1 < clones.size(); ++i) {
    const Vec3 b = Rlt * clones[i].R_W_C() * Vec3(z[i].x(), z[i].y(), 1.0);
    if (!(b.z() > 0.0)) return 1e9;  // rotated behind: certainly a large disparity
    best = std::max(best, (b.head<2>() / b.z() - z.back()).norm());
  }
  return best;
}

}  // namespace evio::estimator

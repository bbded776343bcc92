#include "evio/experiments/nees.h"

#include <Eigen/Cholesky>
#include <algorithm>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/chi_squared.h"

namespace evio::experiments {

namespace {

/// eᵀ P⁻¹ e by Cholesky; false when P is not positive definite.
bool mahalanobis(const Mat3& P, const Vec3& e, double* out) {
  const Eigen::LLT<Mat3> llt(P);
  if (llt.info() != Eigen::Success || !(P.diagonal().array() > 0.0).all()) return false;
  const Vec3 w = llt.matrixL().solve(e);
  *out = w.squaredNorm();
  return true;
}

}  // namespace

void NeesOptions::validate() const {
  requireField(rotation_error == "local" || rotation_error == "global", "rotation_error",
               "must be local or global (got '" + rotation_error + "')");
}

NeesMetrics poseNees(const Association& association, const Alignment& alignment,
                     const std::vector<io::StampedPoseCovariance>& covariance, const NeesOptions& options) {
  options.validate();
  NeesMetrics m;
  if (covariance.empty()) return m;
  const bool local = options.rotation_error == "local";
  const auto [lo, hi] = neesBounds(6, 1);
  std::size_t in_bounds = 0;
  for (const AssociatedPose& a : association.poses) {
    const auto it = std::lower_bound(covariance.begin(), covariance.end(), a.t_ns,
                                     [](const io::StampedPoseCovariance& c, TimeNs t) { return c.t_ns < t; });
    if (it == covariance.end() || it->t_ns != a.t_ns) continue;
    const Pose gt = options.use_alignment ? alignment.transform.applyInverse(a.T_W_gt) : a.T_W_gt;
    const Vec3 e_p = gt.translation() - a.T_W_es.translation();
    const Mat3 R_es = a.T_W_es.rotation();
    const Vec3 e_r = local ? so3::log(Mat3(R_es.transpose() * gt.rotation()))
                           : so3::log(Mat3(gt.rotation() * R_es.transpose()));
    NeesSample s;
    s.t_ns = a.t_ns;
    if (!mahalanobis(it->cov_position, e_p, &s.position) || !mahalanobis(it->cov_orientation, e_r, &s.orientation)) {
      ++m.singular;
      continue;
    }
    s.pose = s.position + s.orientation;
    m.mean_pose += s.pose;
    m.mean_position += s.position;
    m.mean_orientation += s.orientation;
    if (s.pose >= lo && s.pose <= hi) ++in_bounds;
    m.samples.push_back(s);
  }
  m.available = !m.samples.empty() || m.singular > 0;
  m.poses = m.samples.size();
  if (m.poses > 0) {
    const double n = static_cast<double>(m.poses);
    m.mean_pose /= n;
    m.mean_position /= n;
    m.mean_orientation /= n;
    m.share_in_bounds = static_cast<double>(in_bounds) / n;
  }
  return m;
}

std::pair<double, double> neesBounds(int dof, int runs, double probability) {
  require(dof > 0 && runs > 0 && probability > 0.0 && probability < 1.0, "neesBounds: bad arguments");
  const double k = static_cast<double>(dof) * runs;
  return {estimator::chi2Quantile(0.5 * (1.0 - probability), k) / runs,
          estimator::chi2Quantile(0.5 * (1.0 + probability), k) / runs};
}

}  // namespace evio::experiments

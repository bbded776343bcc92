#include "evio/estimator/backend/updater.h"

#include <cmath>

#include "evio/estimator/backend/ekf_update.h"

namespace evio::estimator {

void Updater::constrainAt(const FilterState& x, MatX* H) const {
  if (!options().observability_constraint || H->rows() == 0) return;
  const VecX n = x.yawDirection(*ctx_.fej_imu);
  *H -= (*H * n) * (n.transpose() / n.squaredNorm());
}

bool Updater::passesGate(const MatX& H, const VecX& r, double sigma2, double threshold) const {
  return !(mahalanobisSquared(H, r, state().P, sigma2) > threshold);  // NaN passes, as it always did
}

bool Updater::passesRecordedGate(const MatX& H, const VecX& r, double sigma2, double threshold) const {
  const double m = mahalanobisSquared(H, r, state().P, sigma2);
  const bool pass = !(m > threshold);  // NaN passes, as it always did
  if (InnovationStats* s = ctx_.innovation) {
    if (std::isfinite(m)) {
      s->nis += m;
      s->dof += static_cast<int>(r.size());
      if (pass) {
        s->nis_accepted += m;
        s->dof_accepted += static_cast<int>(r.size());
      }
    }
    ++(pass ? s->accepted : s->rejected);
  }
  return pass;
}

bool Updater::constrainAndUpdate(MatX H, const VecX& r, double sigma2) const {
  constrain(&H);
  return ekfUpdate(state(), H, r, sigma2, options().joseph_form);
}

TriangulationOptions Updater::triangulationOptions(double sigma_z, double prior_sigma_rho) const {
  TriangulationOptions t;
  t.max_iterations = options().triangulation_max_iterations;
  t.tolerance = options().triangulation_tolerance;
  t.min_depth_m = options().triangulation_min_depth_m;
  if (options().triangulate_when_better_than_prior) {
    t.sigma_z = sigma_z;
    t.max_sigma_rho = prior_sigma_rho;
  }
  return t;
}

double Updater::minParallaxNormalized(const Camera& camera, double parallax_px) const {
  const Vec4 k = camera.intrinsics();
  return parallax_px / (0.5 * (k(0) + k(1)));
}

}  // namespace evio::estimator

#include "evio/estimator/backend/aux_updaters.h"

#include <algorithm>
#include <cmath>

#include "evio/estimator/backend/range_update.h"

namespace evio::estimator {

bool RangeUpdater::update(double range_m) {
  if (!(range_m >= sensor_.min_range_m && range_m <= sensor_.max_range_m)) {
    ++stats().range_rejected;
    return true;
  }
  const ImuState& x = state().imu;
  {
    // Beam hit point h = o + range · d, o = p_W_B + R_W_B p_B_L, d = R_W_B R_B_L e_z,
    // kept for depth priors whatever the update below makes of the reading:
    // when the SLAM features' depths are wrong (a prior made for another
    // scene) the gate rejects the reading, and new features should still take
    // the measured range rather than that prior.
    const Mat3 R = x.q_W_B.toRotationMatrix();
    const Vec3 o = x.p_W_B + R * sensor_.T_B_L.translation();
    hit_ = std::pair{x.t_ns, Vec3(o + range_m * (R * sensor_.T_B_L.rotation().col(2)))};
  }
  Eigen::Matrix<double, 1, Eigen::Dynamic> H1;
  double r = 0.0;
  constexpr double kDeg = M_PI / 180.0;
  if (!rangeResidual(state(), sensor_.T_B_L, range_m, options().range_max_feature_angle_deg * kDeg, &H1, &r)) {
    ++stats().range_rejected;
    return true;
  }
  const double sigma =
      options().range_sigma_m > 0.0 ? options().range_sigma_m : std::max(sensor_.noise_sigma_m, 1e-3);
  const VecX rv = VecX::Constant(1, r);
  MatX H = H1;
  constrain(&H);
  if (!passesGate(H, rv, sigma * sigma, (*chi2_)(1))) {
    ++stats().range_rejected;
    return true;
  }
  // The gated rows are constrained once more by the update (a projection:
  // idempotent up to round-off).
  if (!constrainAndUpdate(H, rv, sigma * sigma)) return false;
  ++stats().range_updates;
  return true;
}

bool ZeroVelocityUpdater::update() {
  MatX H = MatX::Zero(3, state().dim());
  H.block<3, 3>(0, kIdxV).setIdentity();
  const VecX r = -state().imu.v_W;
  const double s = options().zero_velocity_sigma_mps;
  if (!constrainAndUpdate(H, r, s * s)) return false;
  ++stats().zero_velocity_updates;
  return true;
}

}  // namespace evio::estimator

#include "evio/estimator/backend/range_update.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "evio/core/so3.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

bool rangeToPlane(const Vec3& o, const Vec3& d, const Vec3& q1, const Vec3& q2, const Vec3& q3, double* range,
                  Eigen::Matrix<double, 1, 3>* d_r_d_o, Eigen::Matrix<double, 1, 3>* d_r_d_d,
                  Eigen::Matrix<double, 1, 9>* d_r_d_q) {
  const Vec3 a = q2 - q1, b = q3 - q1;
  const Vec3 n = a.cross(b);
  const double nn = n.norm();
  if (!(nn > 1e-12 * std::max(1.0, a.squaredNorm() + b.squaredNorm()))) return false;
  const double nd = n.dot(d);
  if (!(std::abs(nd) > 0.1 * nn * d.norm())) return false;  // beam within ~84° of the plane normal
  const Vec3 w = q1 - o;
  const double num = n.dot(w);
  *range = num / nd;
  if (d_r_d_o != nullptr) *d_r_d_o = -n.transpose() / nd;
  if (d_r_d_d != nullptr) *d_r_d_d = -num * n.transpose() / (nd * nd);
  if (d_r_d_q != nullptr) {
    // ∂r/∂n = wᵀ/(n·d) − (n·w) dᵀ/(n·d)²;  n = a × b: ∂n/∂a = −[b]x, ∂n/∂b = [a]x.
    const Eigen::Matrix<double, 1, 3> d_r_d_n = w.transpose() / nd - num * d.transpose() / (nd * nd);
    const Mat3 A = so3::hat(a), B = so3::hat(b);
    d_r_d_q->segment<3>(0) = d_r_d_n * (B - A) + n.transpose() / nd;
    d_r_d_q->segment<3>(3) = d_r_d_n * (-B);
    d_r_d_q->segment<3>(6) = d_r_d_n * A;
  }
  return true;
}

std::optional<double> inverseDepthOnLevelPlane(const CameraClone& camera, const Vec2& z, double plane_z_m,
                                               double min_depth_m) {
  const Vec3 u = camera.R_W_C() * Vec3(z.x(), z.y(), 1.0);
  if (!(u.z() < -0.1 * u.norm())) return std::nullopt;  // near or above the horizon
  const double s = (plane_z_m - camera.p_W_C.z()) / u.z();
  if (!std::isfinite(s) || !(s >= min_depth_m)) return std::nullopt;
  return 1.0 / s;
}

bool rangeResidual(const FilterState& state, const Pose& T_B_L, double measured_range_m, double max_angle_rad,
                   Eigen::Matrix<double, 1, Eigen::Dynamic>* H, double* r) {
  const Mat3 R = state.imu.q_W_B.toRotationMatrix();
  const Vec3 p_B_L = T_B_L.translation();
  const Vec3 d_B = T_B_L.rotation().col(2);
  const Vec3 o = state.imu.p_W_B + R * p_B_L;
  const Vec3 d = R * d_B;
  // The three features nearest to the beam in angle.
  std::vector<std::pair<double, std::size_t>> cand;
  for (std::size_t j = 0; j < state.features.size(); ++j) {
    const int a = state.findClone(state.features[j].anchor_clone_id);
    if (a < 0 || !(state.features[j].abr.z() > 0.0)) continue;
    const Vec3 q = anchoredToWorld(state.clones[static_cast<std::size_t>(a)], state.features[j].abr);
    const Vec3 ray = q - o;
    const double angle = std::atan2(ray.cross(d).norm(), ray.dot(d));
    if (angle <= max_angle_rad) cand.emplace_back(angle, j);
  }
  if (cand.size() < 3) return false;
  std::partial_sort(cand.begin(), cand.begin() + 3, cand.end());
  Vec3 q[3];
  Mat36 Jq_anchor[3];
  Mat3 Jq_f[3];
  for (int k = 0; k < 3; ++k) {
    const SlamFeature& f = state.features[cand[static_cast<std::size_t>(k)].second];
    const auto a = static_cast<std::size_t>(state.findClone(f.anchor_clone_id));
    q[k] = anchoredToWorld(state.clones[a], f.abr, &Jq_anchor[k], &Jq_f[k]);
  }
  double predicted = 0.0;
  Eigen::Matrix<double, 1, 3> Jo, Jd;
  Eigen::Matrix<double, 1, 9> Jq;
  if (!rangeToPlane(o, d, q[0], q[1], q[2], &predicted, &Jo, &Jd, &Jq) || !(predicted > 0.0)) return false;
  H->setZero(1, state.dim());
  // ∂o/∂δp = I, ∂o/∂δθ = −R [p_B_L]x, ∂d/∂δθ = −R [d_B]x.
  H->segment<3>(kIdxP) = Jo;
  H->segment<3>(kIdxTheta) = -Jo * R * so3::hat(p_B_L) - Jd * R * so3::hat(d_B);
  for (int k = 0; k < 3; ++k) {
    const std::size_t j = cand[static_cast<std::size_t>(k)].second;
    const auto a = static_cast<std::size_t>(state.findClone(state.features[j].anchor_clone_id));
    const Eigen::Matrix<double, 1, 3> Jk = Jq.segment<3>(3 * k);
    H->segment<6>(state.cloneIndex(a)) += Jk * Jq_anchor[k];
    H->segment<3>(state.featureIndex(j)) += Jk * Jq_f[k];
  }
  *r = measured_range_m - predicted;
  return true;
}

}  // namespace evio::estimator

#include "evio/estimator/backend/slam_features.h"

#include <Eigen/Cholesky>
#include <Eigen/QR>
#include <cmath>
#include <limits>

#include "evio/core/camera/camera_common.h"
#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

bool slamResidual(const FilterState& state, std::size_t j, std::size_t c, const Vec2& z,
                  Eigen::Matrix<double, 2, Eigen::Dynamic>* H, Vec2* r) {
  const SlamFeature& f = state.features[j];
  const int a = state.findClone(f.anchor_clone_id);
  if (a < 0) return false;
  const CameraClone& anchor = state.clones[static_cast<std::size_t>(a)];
  Vec2 zh;
  Mat26 Ha, Hc;
  Mat23 Hf;
  if (!projectAnchoredFeature(anchor, state.clones[c], f.abr, &zh, &Ha, &Hc, &Hf)) return false;
  H->setZero(2, state.dim());
  H->block<2, 6>(0, state.cloneIndex(static_cast<std::size_t>(a))) += Ha;
  H->block<2, 6>(0, state.cloneIndex(c)) += Hc;
  H->block<2, 3>(0, state.featureIndex(j)) = Hf;
  *r = z - zh;
  if (state.hasTrackErrors()) {  // z = π(h) + e + n
    H->block<2, 2>(0, state.featureIndex(j) + kFeatureDim).setIdentity();
    *r -= f.track_error;
  }
  if (state.has_image_shift && state.isNewestClone(c)) {  // z = π(h) + s + n, s the newest clone's
    H->block<2, 2>(0, state.imageShiftIndex()).setIdentity();
    *r -= state.image_shift;
  }
  return true;
}

bool slamSecondOrderCovariance(const FilterState& state, std::size_t j, std::size_t c, Mat2* cov) {
  const SlamFeature& f = state.features[j];
  const int a = state.findClone(f.anchor_clone_id);
  if (a < 0) return false;
  const CameraClone& anchor = state.clones[static_cast<std::size_t>(a)];
  const CameraClone& clone = state.clones[c];
  const Mat3 Rit = clone.R_W_C().transpose();
  const Vec3 dp = anchor.p_W_C - clone.p_W_C;
  const Vec3 h = Rit * (anchor.R_W_C() * Vec3(f.abr.x(), f.abr.y(), 1.0) + f.abr.z() * dp);
  if (!(h.allFinite() && h.z() > 0.0)) return false;
  // G over the state: +R_iᵀ on δp_a, −R_iᵀ on δp_i, [R_iᵀ dp]× on δθ_i (the
  // position blocks cancel when the clone is the anchor).
  Eigen::Matrix<double, 3, Eigen::Dynamic> G = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, state.dim());
  G.block<3, 3>(0, state.cloneIndex(static_cast<std::size_t>(a)) + kCloneP) += Rit;
  G.block<3, 3>(0, state.cloneIndex(c) + kCloneP) -= Rit;
  G.block<3, 3>(0, state.cloneIndex(c) + kCloneTheta) += so3::hat(Rit * dp);
  const int rho = state.featureIndex(j) + 2;
  const Eigen::Matrix<double, 3, Eigen::Dynamic> GP = G * state.P;
  const Vec3 GP_rho = GP.col(rho);
  const Mat3 cov_h = state.P(rho, rho) * (GP * G.transpose()) + GP_rho * GP_rho.transpose();
  const Mat23 Pi = dNormalizedDPoint(h);
  *cov = Pi * cov_h * Pi.transpose();
  return cov->allFinite();
}

namespace {

// One exact first-order Gauss–Markov step of the 2-vector x whose error
// block starts at P's index k, φ = exp(−Δt/τ), stationary covariance Σ:
//   x ← φ x,  P's rows and columns k, k+1 × φ,  P_kk += (1 − φ²) Σ.
void gaussMarkovStep(MatX& P, int k, double phi, const Mat2& stationary, Vec2* x) {
  *x *= phi;
  P.middleRows(k, 2) *= phi;
  P.middleCols(k, 2) *= phi;
  P.block<2, 2>(k, k) += (1.0 - phi * phi) * stationary;
}

}  // namespace

void decayTrackErrors(FilterState& state, double dt_s, double time_s) {
  if (!state.hasTrackErrors() || !(dt_s > 0.0)) return;
  const double phi = std::exp(-dt_s / time_s);
  for (std::size_t j = 0; j < state.features.size(); ++j)
    gaussMarkovStep(state.P, state.featureIndex(j) + kFeatureDim, phi, state.track_error_cov,
                    &state.features[j].track_error);
}

void decayImageShift(FilterState& state, double dt_s) {
  if (!state.has_image_shift || !(dt_s > 0.0)) return;
  gaussMarkovStep(state.P, state.imageShiftIndex(), std::exp(-dt_s / state.image_shift_time_s),
                  state.image_shift_cov, &state.image_shift);
}

Mat2 whitenWithExtraCovariance(const Mat2& whiten, double sigma_z, const Mat2& extra) {
  const Mat2 W_inv = whiten.inverse();
  const Mat2 cov = sigma_z * sigma_z * W_inv * W_inv.transpose() + extra;
  const Eigen::LLT<Mat2> llt(0.5 * (cov + cov.transpose()));
  if (llt.info() != Eigen::Success) return whiten;
  // cov = L Lᵀ ⇒ (σ_z L⁻¹) cov (σ_z L⁻¹)ᵀ = σ_z² I.
  return sigma_z * llt.matrixL().solve(Mat2::Identity());
}

double correlatedSampleVarianceFactor(double dt_s, double time_s) {
  if (!(time_s > 0.0)) return 1.0;
  if (!(dt_s > 0.0)) return std::numeric_limits<double>::infinity();
  return 1.0 / std::tanh(0.5 * dt_s / time_s);
}

namespace {

// A bearing taken from an observation of the newest clone, z = b + s + n,
// is b̂ = z − ŝ and δb = −δs − n: the just-added feature's (α, β) (whose
// δb = −n so far) and its mean move by the shift, P ← T P Tᵀ with T the
// identity minus I₂ from the shift's columns into (α, β)'s rows.
void bearingCarriesTheShift(FilterState& state, std::size_t c) {
  if (!state.has_image_shift || !state.isNewestClone(c)) return;
  const std::size_t j = state.features.size() - 1;
  const int a = state.featureIndex(j);
  const int k = state.imageShiftIndex();
  state.features[j].abr.head<2>() -= state.image_shift;
  const MatX shift_rows = state.P.middleRows(k, kImageShiftDim);
  state.P.middleRows(a, 2) -= shift_rows;
  const MatX shift_cols = state.P.middleCols(k, kImageShiftDim);
  state.P.middleCols(a, 2) -= shift_cols;
}

}  // namespace

void addSlamFeatureWithPrior(FilterState& state, FeatureId id, std::size_t c, const Vec2& z, double rho0,
                             double sigma_rho0, double sigma_z, const Mat2& whiten) {
  SlamFeature f;
  f.id = id;
  f.anchor_clone_id = state.clones[c].id;
  f.abr = Vec3(z.x(), z.y(), rho0);
  // (α, β) = z: the observation's covariance Σ_z = σ_z² W⁻¹ W⁻ᵀ (feature_track.h).
  const Mat2 W_inv = whiten.inverse();
  Mat3 P_ff = Mat3::Zero();
  P_ff.topLeftCorner<2, 2>() = sigma_z * sigma_z * W_inv * W_inv.transpose();
  P_ff(2, 2) = sigma_rho0 * sigma_rho0;
  state.addFeature(f, P_ff, Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, state.dim()));
  bearingCarriesTheShift(state, c);
}

void addSlamFeatureFromSceneDepth(FilterState& state, FeatureId id, std::size_t c, const Vec2& z,
                                  double sigma_delta, double sigma_z, const Mat2& whiten) {
  require(state.has_scene_depth, "addSlamFeatureFromSceneDepth: the state has no scene depth");
  SlamFeature f;
  f.id = id;
  f.anchor_clone_id = state.clones[c].id;
  f.abr = Vec3(z.x(), z.y(), state.scene_rho);
  const int s = state.sceneDepthIndex();
  const Mat2 W_inv = whiten.inverse();
  Mat3 P_ff = Mat3::Zero();
  P_ff.topLeftCorner<2, 2>() = sigma_z * sigma_z * W_inv * W_inv.transpose();
  P_ff(2, 2) = state.P(s, s) + sigma_delta * sigma_delta;
  // δρ = δρ_s + δ: cov(δρ, δx) = cov(δρ_s, δx) for every other entry x.
  Eigen::Matrix<double, 3, Eigen::Dynamic> P_fx = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, state.dim());
  P_fx.row(2) = state.P.row(s);
  state.addFeature(f, P_ff, P_fx);
  bearingCarriesTheShift(state, c);
}

bool splitTriangulatedInit(const FilterState& state, const FeatureTrack& track, const Vec3& abr, double sigma2,
                           SlamFeature* f, Mat3* P_ff, Eigen::Matrix<double, 3, Eigen::Dynamic>* P_fx, MatX* H2,
                           VecX* r2, const std::function<void(MatX*)>& constrain, const InverseDepthPrior* prior) {
  if (track.observations.size() < 2) return false;
  const int a = state.findClone(track.observations.back().clone_id);
  if (a < 0) return false;
  const CameraClone& anchor = state.clones[static_cast<std::size_t>(a)];
  std::vector<const TrackObservation*> obs;
  for (const TrackObservation& o : track.observations)
    if (state.findClone(o.clone_id) >= 0) obs.push_back(&o);
  const Eigen::Index m_obs = 2 * static_cast<Eigen::Index>(obs.size());
  if (m_obs < 4) return false;
  const Eigen::Index m = m_obs + (prior != nullptr ? 1 : 0);
  MatX H_x = MatX::Zero(m, state.dim());
  MatX H_f(m, 3);
  VecX r(m);
  for (std::size_t i = 0; i < obs.size(); ++i) {
    const std::size_t c = static_cast<std::size_t>(state.findClone(obs[i]->clone_id));
    Vec2 zh;
    Mat26 Ha, Hc;
    Mat23 Hf;
    if (!projectAnchoredFeature(anchor, state.clones[c], abr, &zh, &Ha, &Hc, &Hf)) return false;
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
    H_x.block<2, 6>(row, state.cloneIndex(static_cast<std::size_t>(a))) += Ha;
    H_x.block<2, 6>(row, state.cloneIndex(c)) += Hc;
    H_f.block<2, 3>(row, 0) = Hf;
    r.segment<2>(row) = obs[i]->whiten * (obs[i]->z - zh);  // whitened to σ_z² I (feature_track.h)
    H_x.middleRows<2>(row) = obs[i]->whiten * H_x.middleRows<2>(row);
    H_f.middleRows<2>(row) = obs[i]->whiten * H_f.middleRows<2>(row);
    addImageShiftToRows(state, c, obs[i]->whiten, row, &H_x, &r);
  }
  if (prior != nullptr) {
    // The prior as one more row, ρ0 = ρ + w with w ~ N(0, σ_ρ0²), whitened to σ_z²; no pose in it.
    const double w = std::sqrt(sigma2) / prior->sigma;
    H_f.row(m - 1) = Eigen::RowVector3d(0.0, 0.0, w);
    r(m - 1) = w * (prior->rho - abr.z());
  }
  if (constrain) constrain(&H_x);
  const Eigen::HouseholderQR<MatX> qr(H_f);
  const MatX QtH = qr.householderQ().adjoint() * H_x;
  const VecX Qtr = qr.householderQ().adjoint() * r;
  const Mat3 R1 = qr.matrixQR().topRows(3).triangularView<Eigen::Upper>();
  const double d = std::abs(R1(0, 0) * R1(1, 1) * R1(2, 2));
  if (!(d > 1e-12) || !std::isfinite(d)) return false;
  const Mat3 R1inv = R1.inverse();
  const MatX H1 = QtH.topRows(3);
  const MatX H1P = H1 * state.P;
  f->id = track.id;
  f->anchor_clone_id = anchor.id;
  f->abr = abr + R1inv * Qtr.head<3>();
  f->gate_failures = 0;
  Mat3 S1 = H1P * H1.transpose();
  S1.diagonal().array() += sigma2;
  *P_ff = R1inv * S1 * R1inv.transpose();
  *P_ff = 0.5 * (*P_ff + P_ff->transpose()).eval();
  *P_fx = -R1inv * H1P;
  *H2 = QtH.bottomRows(m - 3);
  *r2 = Qtr.tail(m - 3);
  return f->abr.allFinite() && P_ff->allFinite();
}

double slamMahalanobis(const FilterState& state, const MatX& H, const VecX& r, double sigma2) {
  return mahalanobisSquared(H, r, state.P, sigma2);
}

bool slamUpdate(FilterState& state, const MatX& H, const VecX& r, double sigma2, bool joseph) {
  return ekfUpdate(state, H, r, sigma2, joseph);
}

bool reanchorSlamFeature(FilterState& state, std::size_t j, std::size_t to, const VecX* yaw_direction) {
  SlamFeature& f = state.features[j];
  const int from = state.findClone(f.anchor_clone_id);
  if (from < 0) return false;
  if (static_cast<std::size_t>(from) == to) return true;
  Vec3 abr_new;
  Mat36 J_from, J_to;
  Mat3 J_f;
  if (!reanchorFeature(state.clones[static_cast<std::size_t>(from)], state.clones[to], f.abr, &abr_new, &J_from,
                       &J_to, &J_f))
    return false;
  Eigen::Matrix<double, 3, Eigen::Dynamic> J = Eigen::Matrix<double, 3, Eigen::Dynamic>::Zero(3, state.dim());
  J.block<3, 6>(0, state.cloneIndex(static_cast<std::size_t>(from))) = J_from;
  J.block<3, 6>(0, state.cloneIndex(to)) = J_to;
  const int k = state.featureIndex(j);
  J.block<3, 3>(0, k) = J_f;
  if (yaw_direction != nullptr) {
    // The anchored parameters have no component along n: keep J n = 0.
    const VecX& n = *yaw_direction;
    J -= (J * n) * (n.transpose() / n.squaredNorm());
  }
  // P' = T P Tᵀ: only the feature's rows and columns change.
  const Eigen::Matrix<double, 3, Eigen::Dynamic> C = J * state.P;  // new cross-covariance row block
  const Mat3 P_ff = C * J.transpose();
  state.P.middleRows(k, 3) = C;
  state.P.middleCols(k, 3) = C.transpose();
  state.P.block<3, 3>(k, k) = 0.5 * (P_ff + P_ff.transpose());
  f.abr = abr_new;
  f.anchor_clone_id = state.clones[to].id;
  return true;
}

}  // namespace evio::estimator

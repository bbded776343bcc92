#include "evio/estimator/backend/msckf_update.h"

#include <Eigen/Cholesky>
#include <cmath>

#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

void gatherTrack(const FilterState& state, const FeatureTrack& track, std::vector<CameraClone>* clones,
                 std::vector<std::size_t>* clone_positions, std::vector<Vec2>* z, std::vector<Mat2>* whiten) {
  clones->clear();
  clone_positions->clear();
  z->clear();
  if (whiten != nullptr) whiten->clear();
  for (const TrackObservation& o : track.observations) {
    const int i = state.findClone(o.clone_id);
    if (i < 0) continue;
    clones->push_back(state.clones[static_cast<std::size_t>(i)]);
    clone_positions->push_back(static_cast<std::size_t>(i));
    z->push_back(o.z);
    if (whiten != nullptr) whiten->push_back(o.whiten);
  }
}

namespace {

// A track's observations in the clones still in the window, with their
// whitening matrices (gatherTrack).
struct TrackInWindow {
  std::vector<CameraClone> clones;
  std::vector<std::size_t> positions;
  std::vector<Vec2> z;
  std::vector<Mat2> whiten;
};

TrackInWindow trackInWindow(const FilterState& state, const FeatureTrack& track) {
  TrackInWindow t;
  gatherTrack(state, track, &t.clones, &t.positions, &t.z, &t.whiten);
  return t;
}

// Rows already whitened one by one (W_i) share the track's error e(t_i):
// C/σ_z² = I + [ρ_ij W_i Σ_e W_jᵀ / σ_z²], ρ_ij = exp(−|t_i − t_j|/τ); the
// rows are replaced by L⁻¹ rows, C/σ_z² = L Lᵀ, so their noise is σ_z² I again.
bool whitenSharedTrackError(const FilterState& state, const std::vector<CameraClone>& clones,
                            const std::vector<Mat2>& W, double sigma2, MatX* H_x, MatX* H_f, VecX* r) {
  if (!(sigma2 > 0.0)) return false;
  const auto n = static_cast<Eigen::Index>(clones.size());
  MatX C = MatX::Identity(2 * n, 2 * n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const double dt = std::abs(nsToSeconds(clones[static_cast<std::size_t>(i)].t_ns -
                                             clones[static_cast<std::size_t>(j)].t_ns));
      const double rho = std::exp(-dt / state.track_error_time_s);
      C.block<2, 2>(2 * i, 2 * j) +=
          rho * W[static_cast<std::size_t>(i)] * state.track_error_cov * W[static_cast<std::size_t>(j)].transpose() / sigma2;
    }
  const Eigen::LLT<MatX> llt(0.5 * (C + C.transpose()));
  if (llt.info() != Eigen::Success) return false;
  llt.matrixL().solveInPlace(*H_x);
  llt.matrixL().solveInPlace(*H_f);
  llt.matrixL().solveInPlace(*r);
  return true;
}

// The track's rows, whitened for a shared track error when the state
// carries one, projected on the left null space of its point columns H_f.
bool projectTrackRows(const FilterState& state, const std::vector<CameraClone>& clones, const std::vector<Mat2>& W,
                      double sigma2_z, MatX* H_x, MatX* H_f, VecX* r) {
  if (state.hasTrackErrors() && !whitenSharedTrackError(state, clones, W, sigma2_z, H_x, H_f, r)) return false;
  projectOnLeftNullSpace(*H_f, H_x, r);
  return true;
}

}  // namespace

MsckfOutcome msckfResidual(const FilterState& state, const FeatureTrack& track, double min_parallax,
                           const TriangulationOptions& triangulation, MsckfResidual* out, double sigma2_z) {
  const TrackInWindow in_window = trackInWindow(state, track);
  const auto& [clones, pos, z, W] = in_window;
  const std::size_t n = clones.size();
  if (n < 2) return MsckfOutcome::kTooShort;
  if (rotationCompensatedDisparity(clones, z) < min_parallax) return MsckfOutcome::kNoParallax;
  TriangulationResult tri;
  if (!triangulateFeature(clones, z, n - 1, triangulation, &tri)) return MsckfOutcome::kTriangulationFailed;
  if (!knowsDepth(tri, triangulation)) return MsckfOutcome::kDepthUnknown;

  const Eigen::Index m = 2 * static_cast<Eigen::Index>(n);
  MatX H_x = MatX::Zero(m, state.dim());
  MatX H_f(m, 3);
  VecX r(m);
  for (std::size_t i = 0; i < n; ++i) {
    Vec2 zh;
    Mat26 Hc;
    Mat23 Hp;
    if (!projectWorldPoint(clones[i], tri.p_W, &zh, &Hc, &Hp)) return MsckfOutcome::kProjectionFailed;
    // Whitened rows W (z − ẑ) ≈ W H δx + W n, W n ~ N(0, σ_z² I) (feature_track.h).
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
    r.segment<2>(row) = W[i] * (z[i] - zh);
    H_x.block<2, 6>(row, state.cloneIndex(pos[i])) = W[i] * Hc;
    H_f.block<2, 3>(row, 0) = W[i] * Hp;
    addImageShiftToRows(state, pos[i], W[i], row, &H_x, &r);
  }
  if (m <= 3) return MsckfOutcome::kTooShort;
  if (!projectTrackRows(state, clones, W, sigma2_z, &H_x, &H_f, &r)) return MsckfOutcome::kProjectionFailed;
  out->H = std::move(H_x);
  out->r = std::move(r);
  out->p_W = tri.p_W;
  return MsckfOutcome::kOk;
}

namespace {

// The anchored feature (α, β, ρ) in clone a that best explains the track's
// observations together with the depth prior ρ ~ N(ρ0, σ_ρ0²): Gauss–Newton
// on Σ ‖W_i (z_i − π_i(α, β, ρ))‖² / σ_z² + (ρ − ρ0)² / σ_ρ0², started at the
// anchor's own observation and ρ0. A track without parallax says little of
// ρ, so the prior holds it near ρ0.
bool fitFeatureWithDepthPrior(const std::vector<CameraClone>& clones, const std::vector<Vec2>& z,
                              const std::vector<Mat2>& W, std::size_t a, double sigma2_z, double rho0,
                              double sigma_rho0, Vec3* abr) {
  *abr = Vec3(z[a].x(), z[a].y(), rho0);
  const double prior_weight = sigma2_z / (sigma_rho0 * sigma_rho0);  // in units of one whitened row
  for (int iteration = 0; iteration < 5; ++iteration) {
    Mat3 JtJ = Mat3::Zero();
    Vec3 Jtr = Vec3::Zero();
    for (std::size_t i = 0; i < clones.size(); ++i) {
      Vec2 zh;
      Mat23 J;
      if (!projectAnchoredFeature(clones[a], clones[i], *abr, &zh, nullptr, nullptr, &J)) return false;
      const Mat23 Jw = W[i] * J;
      JtJ += Jw.transpose() * Jw;
      Jtr += Jw.transpose() * (W[i] * (z[i] - zh));
    }
    JtJ(2, 2) += prior_weight;
    Jtr(2) += prior_weight * (rho0 - abr->z());
    const Vec3 step = JtJ.ldlt().solve(Jtr);
    if (!step.allFinite()) return false;
    *abr += step;
    if (step.norm() < 1e-10) break;
  }
  return abr->z() >= 0.0;
}

}  // namespace

MsckfOutcome rotationResidual(const FilterState& state, const FeatureTrack& track, MsckfResidual* out,
                              double sigma2_z, double rho0, double sigma_rho0) {
  const TrackInWindow in_window = trackInWindow(state, track);
  const auto& [clones, pos, z, W] = in_window;
  const std::size_t n = clones.size();
  if (n < 2) return MsckfOutcome::kTooShort;
  const std::size_t a = n - 1;
  Vec3 abr;
  if (!fitFeatureWithDepthPrior(clones, z, W, a, sigma2_z, rho0, sigma_rho0, &abr))
    return MsckfOutcome::kProjectionFailed;

  const Eigen::Index m = 2 * static_cast<Eigen::Index>(n);
  MatX H_x = MatX::Zero(m, state.dim());
  MatX H_f(m, 3);
  VecX r(m);
  const Eigen::Index anchor_col = state.cloneIndex(pos[a]);
  for (std::size_t i = 0; i < n; ++i) {
    Vec2 zh;
    Mat26 Ha, Hc;
    Mat23 Hf;
    if (!projectAnchoredFeature(clones[a], clones[i], abr, &zh, &Ha, &Hc, &Hf)) return MsckfOutcome::kProjectionFailed;
    const Eigen::Index row = 2 * static_cast<Eigen::Index>(i);
    r.segment<2>(row) = W[i] * (z[i] - zh);
    H_x.block<2, 6>(row, state.cloneIndex(pos[i])) += W[i] * Hc;
    H_x.block<2, 6>(row, anchor_col) += W[i] * Ha;
    H_f.block<2, 3>(row, 0) = W[i] * Hf;
    addImageShiftToRows(state, pos[i], W[i], row, &H_x, &r);
  }
  if (!projectTrackRows(state, clones, W, sigma2_z, &H_x, &H_f, &r)) return MsckfOutcome::kProjectionFailed;
  out->H = std::move(H_x);
  out->r = std::move(r);
  out->p_W = Vec3::Zero();
  return MsckfOutcome::kOk;
}

}  // namespace evio::estimator

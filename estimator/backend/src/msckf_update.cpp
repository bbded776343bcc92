#include "evio/estimator/backend/msckf_update.h"

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

MsckfOutcome msckfResidual(const FilterState& state, const FeatureTrack& track, double min_parallax,
                           const TriangulationOptions& triangulation, MsckfResidual* out) {
  std::vector<CameraClone> clones;
  std::vector<std::size_t> pos;
  std::vector<Vec2> z;
  std::vector<Mat2> W;
  gatherTrack(state, track, &clones, &pos, &z, &W);
  const std::size_t n = clones.size();
  if (n < 2) return MsckfOutcome::kTooShort;
  if (rotationCompensatedDisparity(clones, z) < min_parallax) return MsckfOutcome::kNoParallax;
  TriangulationResult tri;
  if (!triangulateFeature(clones, z, n - 1, triangulation, &tri)) return MsckfOutcome::kTriangulationFailed;
  if (!knowsDepth(tri, triangulation)) return MsckfOutcome::kNoParallax;

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
  }
  if (m <= 3) return MsckfOutcome::kTooShort;
  projectOnLeftNullSpace(H_f, &H_x, &r);
  out->H = std::move(H_x);
  out->r = std::move(r);
  out->p_W = tri.p_W;
  return MsckfOutcome::kOk;
}

}  // namespace evio::estimator

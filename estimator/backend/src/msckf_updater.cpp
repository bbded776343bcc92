#include "evio/estimator/backend/msckf_updater.h"

#include <cmath>
#include <utility>

#include "evio/estimator/backend/msckf_update.h"

namespace evio::estimator {

namespace {

UpdateRows stackRows(const std::vector<MsckfResidual>& used, Eigen::Index dim) {
  Eigen::Index rows = 0;
  for (const MsckfResidual& u : used) rows += u.r.size();
  UpdateRows out{MatX(rows, dim), VecX(rows)};
  Eigen::Index row = 0;
  for (const MsckfResidual& u : used) {
    out.H.middleRows(row, u.H.rows()) = u.H;
    out.r.segment(row, u.r.size()) = u.r;
    row += u.r.size();
  }
  return out;
}

}  // namespace

UpdateRows MsckfUpdater::residuals(const std::vector<FeatureId>& ids, TrackMap* tracks) {
  const TriangulationOptions tri = triangulationOptions(std::sqrt(sigma2_), fixedDepthPriorSigma());
  const double min_parallax = minParallaxNormalized(camera_, options().min_parallax_px);
  std::vector<MsckfResidual> used;
  used_.clear();
  for (const FeatureId id : ids) {
    FeatureTrack& track = (*tracks)[id];
    MsckfResidual res;
    MsckfOutcome outcome = msckfResidual(state(), track, min_parallax, tri, &res, sigma2_);
    bool rotation = false;
    if (outcome == MsckfOutcome::kNoParallax || outcome == MsckfOutcome::kDepthUnknown) {
      ++stats().msckf_features_no_parallax;
      // Rotation rows err at second order in the parallax: only below the
      // minimum disparity (docs/algorithms.md "Rotation rows").
      if (options().msckf_rotation_rows && outcome == MsckfOutcome::kNoParallax) {
        outcome = rotationResidual(state(), track, &res, sigma2_, fixedDepthPriorRho(), fixedDepthPriorSigma());
        rotation = true;
      }
    }
    FeatureTrack copy;
    if (options().msckf_iterations > 1) copy = track;
    track.observations.clear();
    if (outcome == MsckfOutcome::kNoParallax || outcome == MsckfOutcome::kDepthUnknown) continue;
    if (outcome != MsckfOutcome::kOk) {
      ++stats().msckf_triangulation_failed;
      continue;
    }
    constrain(&res.H);
    if (!passesRecordedGate(res.H, res.r, sigma2_, (*chi2_)(static_cast<int>(res.r.size())))) {
      ++(rotation ? stats().msckf_rotation_rejected : stats().msckf_features_rejected);
      continue;
    }
    if (rotation) {
      ++stats().msckf_rotation_used;
    } else {
      triangulatedPoints().add(res.p_W);
    }
    used.push_back(std::move(res));
    if (options().msckf_iterations > 1) used_.push_back({std::move(copy), rotation});
  }
  last_count_ = static_cast<int>(used.size());
  stats().msckf_features_used += last_count_;
  return stackRows(used, state().dim());
}

UpdateRows MsckfUpdater::relinearize(const FilterState& x) const {
  const TriangulationOptions tri = triangulationOptions(std::sqrt(sigma2_), fixedDepthPriorSigma());
  const double min_parallax = minParallaxNormalized(camera_, options().min_parallax_px);
  std::vector<MsckfResidual> rows;
  for (const UsedTrack& used : used_) {
    MsckfResidual res;
    const MsckfOutcome outcome =
        used.rotation ? rotationResidual(x, used.track, &res, sigma2_, fixedDepthPriorRho(), fixedDepthPriorSigma())
                      : msckfResidual(x, used.track, min_parallax, tri, &res, sigma2_);
    if (outcome != MsckfOutcome::kOk) continue;
    constrainAt(x, &res.H);
    rows.push_back(std::move(res));
  }
  return stackRows(rows, x.dim());
}

}  // namespace evio::estimator

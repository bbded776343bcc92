// The visual update of Backend: one measurement set (backend.h, steps 1-6).
#include <algorithm>
#include <unordered_set>

#include "evio/core/so3.h"
#include "evio/estimator/backend/backend.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/triangulation.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

void Backend::augmentClone() {
  Eigen::Matrix<double, 6, 15> J_imu;
  const Pose T_W_C = cameraPose(state_.imu, sensors_.T_B_C, &J_imu);
  CameraClone clone;
  clone.id = next_clone_id_++;
  clone.t_ns = state_.imu.t_ns;
  clone.p_W_C = clone.p_fej = T_W_C.translation();
  clone.q_W_C = clone.q_fej = T_W_C.quaternion();
  Eigen::Matrix<double, kCloneDim, Eigen::Dynamic> J = Eigen::Matrix<double, kCloneDim, Eigen::Dynamic>::Zero(
      kCloneDim, state_.dim());
  J.leftCols<kImuDim>() = J_imu;
  state_.addClone(clone, J);
}

void Backend::processMeasurementSet(const MeasurementSet& set) {
  ++stats_.measurement_sets;
  augmentClone();
  const std::size_t c = state_.clones.size() - 1;
  const std::int64_t clone_id = state_.clones[c].id;
  const double sigma2 = sigma_z_ * sigma_z_;

  // Undistorted normalised observations, one per feature id.
  std::vector<std::pair<FeatureId, Vec2>> obs;
  obs.reserve(set.features.size());
  std::unordered_set<FeatureId> seen;
  for (const FeatureMeasurement& m : set.features) {
    Vec3 bearing;
    if (!seen.insert(m.id).second) continue;
    if (!sensors_.camera.unproject(m.uv, &bearing) || !(bearing.z() > 1e-6)) {
      ++stats_.features_undistort_failed;
      continue;
    }
    obs.emplace_back(m.id, bearing.head<2>() / bearing.z());
  }

  // SLAM features not observed in this set are lost: marginalise them.
  std::unordered_set<FeatureId> observed;
  for (const auto& [id, z] : obs) observed.insert(id);
  for (std::size_t j = state_.features.size(); j-- > 0;) {
    if (observed.count(state_.features[j].id) == 0) {
      state_.removeFeature(j);
      ++stats_.slam_features_removed;
    }
  }

  // Stacked update: SLAM observations (re-linearised by the iterated update)
  // and MSCKF rows (linear: already null-space projected).
  std::vector<std::pair<FeatureId, Vec2>> slam_obs;
  std::vector<MatX> H_blocks;
  std::vector<VecX> r_blocks;

  // 2. SLAM residuals (Mahalanobis-gated, 2 dof); other observations extend the tracks.
  std::vector<std::size_t> gated_out;
  for (const auto& [id, z] : obs) {
    const int j = state_.findFeature(id);
    if (j < 0) {
      FeatureTrack& tr = tracks_[id];
      tr.id = id;
      tr.observations.push_back({clone_id, z});
      continue;
    }
    Eigen::Matrix<double, 2, Eigen::Dynamic> H;
    Vec2 r;
    SlamFeature& f = state_.features[static_cast<std::size_t>(j)];
    MatX Hc;
    const bool ok = slamResidual(state_, static_cast<std::size_t>(j), c, z, &H, &r);
    if (ok) {
      Hc = H;
      constrain(&Hc);
    }
    if (!ok || mahalanobisSquared(Hc, r, state_.P, sigma2) > slam_chi2_(2)) {
      ++stats_.slam_updates_rejected;
      if (++f.gate_failures >= options_.slam_max_gate_failures) gated_out.push_back(static_cast<std::size_t>(j));
      continue;
    }
    f.gate_failures = 0;
    slam_obs.emplace_back(id, z);
  }

  // SLAM candidates: the longest live tracks with enough observations, for the free slots.
  const int free_slots = options_.max_slam_features - static_cast<int>(state_.features.size()) +
                         static_cast<int>(gated_out.size());
  std::vector<FeatureId> slam_candidates;
  if (free_slots > 0) {
    std::vector<std::pair<std::size_t, FeatureId>> eligible;
    for (const auto& [id, tr] : tracks_)
      if (!tr.observations.empty() && tr.observations.back().clone_id == clone_id &&
          static_cast<int>(tr.observations.size()) >= options_.slam_min_track_length)
        eligible.emplace_back(tr.observations.size(), id);
    std::sort(eligible.begin(), eligible.end(),
              [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
    for (int k = 0; k < free_slots && k < static_cast<int>(eligible.size()); ++k)
      slam_candidates.push_back(eligible[static_cast<std::size_t>(k)].second);
  }
  const std::unordered_set<FeatureId> slam_set(slam_candidates.begin(), slam_candidates.end());

  // 3. MSCKF candidates: tracks about to lose their oldest observation, and lost tracks.
  const bool sliding = static_cast<int>(state_.clones.size()) > options_.window_size;
  const std::int64_t oldest_id = state_.clones.front().id;
  std::vector<FeatureId> msckf_candidates, erase_ids;
  for (auto& [id, tr] : tracks_) {
    const bool live = !tr.observations.empty() && tr.observations.back().clone_id == clone_id;
    const int len = static_cast<int>(tr.observations.size());
    if (!live) {
      if (options_.msckf_use_lost_tracks && len >= options_.msckf_min_track_length) msckf_candidates.push_back(id);
      erase_ids.push_back(id);
    } else if (sliding && slam_set.count(id) == 0 && tr.observations.front().clone_id == oldest_id &&
               len >= options_.msckf_min_track_length) {
      msckf_candidates.push_back(id);
    }
  }
  TriangulationOptions tri;
  tri.max_iterations = options_.triangulation_max_iterations;
  tri.tolerance = options_.triangulation_tolerance;
  tri.min_depth_m = options_.triangulation_min_depth_m;
  const Vec4 k = sensors_.camera.intrinsics();
  const double min_parallax = options_.min_parallax_px / (0.5 * (k(0) + k(1)));
  int msckf_used = 0;
  for (const FeatureId id : msckf_candidates) {
    FeatureTrack& tr = tracks_[id];
    MsckfResidual res;
    const MsckfOutcome outcome = msckfResidual(state_, tr, min_parallax, tri, &res);
    if (outcome == MsckfOutcome::kOk) constrain(&res.H);
    if (outcome == MsckfOutcome::kNoParallax) ++stats_.msckf_features_no_parallax;
    else if (outcome != MsckfOutcome::kOk) ++stats_.msckf_triangulation_failed;
    else if (mahalanobisSquared(res.H, res.r, state_.P, sigma2) > msckf_chi2_(static_cast<int>(res.r.size())))
      ++stats_.msckf_features_rejected;
    else {
      H_blocks.push_back(std::move(res.H));
      r_blocks.push_back(std::move(res.r));
      ++msckf_used;
    }
    tr.observations.clear();  // used (or unusable): never twice
  }
  stats_.msckf_features_used += msckf_used;
  last_msckf_count_ = msckf_used;
  for (const FeatureId id : erase_ids) tracks_.erase(id);

  // 4. One stacked, QR-compressed (iterated) update.
  if (!slam_obs.empty() || !H_blocks.empty()) {
    Eigen::Index rows = 0;
    for (const VecX& r : r_blocks) rows += r.size();
    MatX H(rows, state_.dim());
    VecX r(rows);
    Eigen::Index row = 0;
    for (std::size_t b = 0; b < H_blocks.size(); ++b) {
      H.middleRows(row, H_blocks[b].rows()) = H_blocks[b];
      r.segment(row, r_blocks[b].size()) = r_blocks[b];
      row += r_blocks[b].size();
    }
    const auto slam_rows = [this, &slam_obs, c](const FilterState& x, MatX* Hs, VecX* rs) {
      Hs->setZero(2 * static_cast<Eigen::Index>(slam_obs.size()), x.dim());
      rs->setZero(2 * static_cast<Eigen::Index>(slam_obs.size()));
      for (std::size_t q = 0; q < slam_obs.size(); ++q) {
        Eigen::Matrix<double, 2, Eigen::Dynamic> Hq;
        Vec2 rq;
        const int j = x.findFeature(slam_obs[q].first);
        if (j < 0 || !slamResidual(x, static_cast<std::size_t>(j), c, slam_obs[q].second, &Hq, &rq)) continue;
        Hs->middleRows<2>(2 * static_cast<Eigen::Index>(q)) = Hq;
        rs->segment<2>(2 * static_cast<Eigen::Index>(q)) = rq;
      }
      constrain(Hs);
    };
    if (!iteratedEkfUpdate(state_, slam_rows, H, r, sigma2, options_.iekf_iterations, options_.joseph_form)) {
      setStatus(BackendStatus::Code::kDiverged, "innovation covariance not positive definite");
      return;
    }
  }

  // SLAM features gated out too often, or no longer valid, leave the state.
  std::sort(gated_out.begin(), gated_out.end());
  for (std::size_t q = gated_out.size(); q-- > 0;) {
    state_.removeFeature(gated_out[q]);
    ++stats_.slam_features_removed;
  }
  for (std::size_t j = state_.features.size(); j-- > 0;) {
    if (!state_.features[j].abr.allFinite()) {
      state_.removeFeature(j);
      ++stats_.slam_features_removed;
    }
  }

  // 5. New SLAM features.
  initializeSlamFeatures(slam_candidates);

  // 6. Slide the window.
  if (static_cast<int>(state_.clones.size()) > options_.window_size) slideWindow();
  estimates_.push_back(makeEstimate());
}

std::optional<double> Backend::rangeDepthPrior(const CameraClone& clone, const Vec2& z) const {
  if (!options_.use_range || !(options_.range_prior_relative_sigma > 0.0) || !range_hit_) return std::nullopt;
  if (nsToSeconds(clone.t_ns - range_hit_->first) > options_.range_prior_max_age_s) return std::nullopt;
  return inverseDepthOnLevelPlane(clone, z, range_hit_->second.z(), options_.triangulation_min_depth_m);
}

void Backend::initializeSlamFeatures(const std::vector<FeatureId>& candidates) {
  const std::size_t c = state_.clones.size() - 1;
  const double sigma2 = sigma_z_ * sigma_z_;
  const double rho0 = 1.0 / (2.0 * options_.slam_min_depth_m);
  const double sigma_rho0 = 1.0 / (4.0 * options_.slam_min_depth_m);
  const Vec4 k = sensors_.camera.intrinsics();
  const double min_parallax = options_.min_parallax_px / (0.5 * (k(0) + k(1)));
  TriangulationOptions tri;
  tri.max_iterations = options_.triangulation_max_iterations;
  tri.tolerance = options_.triangulation_tolerance;
  tri.min_depth_m = options_.triangulation_min_depth_m;
  for (const FeatureId id : candidates) {
    if (static_cast<int>(state_.features.size()) >= options_.max_slam_features) break;
    auto it = tracks_.find(id);
    if (it == tracks_.end() || it->second.observations.empty()) continue;
    const FeatureTrack track = it->second;
    tracks_.erase(it);
    bool done = false;
    if (options_.slam_triangulated_init) {
      std::vector<CameraClone> clones;
      std::vector<std::size_t> pos;
      std::vector<Vec2> z;
      gatherTrack(state_, track, &clones, &pos, &z);
      TriangulationResult res;
      if (clones.size() >= 2 && rotationCompensatedDisparity(clones, z) >= min_parallax &&
          triangulateFeature(clones, z, clones.size() - 1, tri, &res)) {
        const SlamInitOutcome outcome =
            addSlamFeatureTriangulated(state_, track, res.abr, sigma2, options_.joseph_form, msckf_chi2_,
                                       [this](MatX* H) { constrain(H); });
        if (outcome == SlamInitOutcome::kUpdateFailed) {
          setStatus(BackendStatus::Code::kDiverged, "innovation covariance not positive definite");
          return;
        }
        done = outcome == SlamInitOutcome::kOk;
        if (done) ++stats_.slam_initialized_triangulated;
      }
    }
    if (done) continue;
    const Vec2& z = track.observations.back().z;
    if (const auto rho = rangeDepthPrior(state_.clones[c], z)) {
      addSlamFeatureWithPrior(state_, id, c, z, *rho, options_.range_prior_relative_sigma * *rho, sigma_z_);
      ++stats_.slam_initialized_range;
    } else {
      addSlamFeatureWithPrior(state_, id, c, z, rho0, sigma_rho0, sigma_z_);
      ++stats_.slam_initialized_prior;
    }
  }
}

void Backend::slideWindow() {
  const std::int64_t oldest = state_.clones.front().id;
  const std::size_t newest = state_.clones.size() - 1;
  for (std::size_t j = state_.features.size(); j-- > 0;) {
    if (state_.features[j].anchor_clone_id != oldest) continue;
    const VecX n = state_.yawDirection(fej_imu_);
    if (reanchorSlamFeature(state_, j, newest, options_.observability_constraint ? &n : nullptr)) {
      ++stats_.slam_reanchored;
    } else {
      state_.removeFeature(j);
      ++stats_.slam_features_removed;
    }
  }
  for (auto it = tracks_.begin(); it != tracks_.end();) {
    auto& o = it->second.observations;
    o.erase(std::remove_if(o.begin(), o.end(), [oldest](const TrackObservation& x) { return x.clone_id == oldest; }),
            o.end());
    it = o.empty() ? tracks_.erase(it) : std::next(it);
  }
  state_.removeClone(0);
}

}  // namespace evio::estimator

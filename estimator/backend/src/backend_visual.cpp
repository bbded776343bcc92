// The visual update of Backend: one measurement set (backend.h, steps 1-6),
// each step one function.
#include <algorithm>
#include <optional>
#include <unordered_set>

#include "evio/estimator/backend/backend.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/slam_features.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {

void Backend::processMeasurementSet(const MeasurementSet& set) {
  ++stats_.measurement_sets;
  innovation_ = InnovationStats{};
  augmentClone();
  const std::size_t c = state_.clones.size() - 1;
  const std::int64_t clone_id = state_.clones[c].id;
  if (c > 0) {
    const double dt_s = nsToSeconds(state_.clones[c].t_ns - state_.clones[c - 1].t_ns);
    slam_.diffuseBearings(dt_s);
    slam_.decayTrackErrors(dt_s);
    decayImageShift(state_, dt_s);
    slam_.diffuseSceneDepth(dt_s);
  }

  const std::vector<FeatureObservation> observations = undistortObservations(set, sensors_.camera, sigma_z_, &stats_);
  slam_.marginalizeUnobserved(observations);
  const SlamGate slam_gate = slam_.gate(observations, c);
  extendTracks(observations, state_, clone_id, &tracks_);

  const int free_slots = options_.max_slam_features - static_cast<int>(state_.features.size()) +
                         static_cast<int>(slam_gate.gated_out.size());
  const std::vector<FeatureId> slam_candidates =
      chooseSlamCandidates(tracks_, state_, clone_id, free_slots,
                           SlamEligibility{.min_length = options_.slam_min_track_length,
                                           .min_span_ns = secondsToNs(options_.slam_min_track_span_s),
                                           .span_min_length = options_.msckf_min_track_length});
  const std::optional<std::size_t> leaving = cloneToMarginalize();
  const bool sliding = leaving == std::size_t{0};  // tracks losing their oldest observation go to the MSCKF
  const MsckfChoice msckf_choice = chooseMsckfTracks(
      tracks_, clone_id, state_.clones.front().id, sliding,
      std::unordered_set<FeatureId>(slam_candidates.begin(), slam_candidates.end()), options_.msckf_min_track_length,
      options_.msckf_use_lost_tracks);
  const UpdateRows msckf_rows = msckf_.residuals(msckf_choice.update, &tracks_);
  for (const FeatureId id : msckf_choice.erase) tracks_.erase(id);

  if (!stackedUpdate(slam_gate.accepted, msckf_rows, c)) {
    setStatus(BackendStatus::Code::kDiverged, "innovation covariance not positive definite");
    return;
  }
  slam_.prune(slam_gate.gated_out);
  if (!slam_.initialize(slam_candidates, &tracks_))
    setStatus(BackendStatus::Code::kDiverged, "innovation covariance not positive definite");
  if (leaving) marginalizeClone(*leaving);
  estimates_.push_back(makeEstimate());
}

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

bool Backend::stackedUpdate(const std::vector<FeatureObservation>& slam_observations, const UpdateRows& msckf_rows,
                            std::size_t c) {
  if (slam_observations.empty() && msckf_rows.r.size() == 0) return true;
  // SLAM rows are re-linearised by the iterated update; MSCKF rows are linear
  // (already null-space projected) and stay fixed.
  const auto slam_rows = [this, &slam_observations, c](const FilterState& x, MatX* H, VecX* r) {
    slam_.relinearize(x, slam_observations, c, H, r);
  };
  if (options_.msckf_iterations > 1 && msckf_rows.r.size() > 0) {
    // The MSCKF tracks re-triangulated and re-linearised at every iterate;
    // the SLAM rows linearised once, at the prior.
    UpdateRows slam_fixed;
    slam_rows(state_, &slam_fixed.H, &slam_fixed.r);
    const auto msckf_relinearized = [this](const FilterState& x, MatX* H, VecX* r) {
      UpdateRows rows = msckf_.relinearize(x);
      *H = std::move(rows.H);
      *r = std::move(rows.r);
    };
    return iteratedEkfUpdate(state_, msckf_relinearized, slam_fixed.H, slam_fixed.r, sigma_z_ * sigma_z_,
                             options_.msckf_iterations, options_.joseph_form, options_.visual_covariance_factor);
  }
  return iteratedEkfUpdate(state_, slam_rows, msckf_rows.H, msckf_rows.r, sigma_z_ * sigma_z_,
                           options_.iekf_iterations, options_.joseph_form, options_.visual_covariance_factor);
}

std::optional<std::size_t> Backend::cloneToMarginalize() const {
  const std::size_t n = state_.clones.size();
  if (n >= 3) {
    const TimeNs spacing = state_.clones[n - 2].t_ns - state_.clones[n - 3].t_ns;
    if (nsToSeconds(spacing) < options_.keyframe_interval_s) return n - 2;
  }
  if (static_cast<int>(n) > options_.window_size) return 0;
  return std::nullopt;
}

void Backend::marginalizeClone(std::size_t i) {
  const std::int64_t leaving = state_.clones[i].id;
  const std::size_t newest = state_.clones.size() - 1;
  for (std::size_t j = state_.features.size(); j-- > 0;) {
    if (state_.features[j].anchor_clone_id != leaving) continue;
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
    o.erase(std::remove_if(o.begin(), o.end(), [leaving](const TrackObservation& x) { return x.clone_id == leaving; }),
            o.end());
    it = o.empty() ? tracks_.erase(it) : std::next(it);
  }
  state_.removeClone(i);
}

}  // namespace evio::estimator

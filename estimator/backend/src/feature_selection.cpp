#include "evio/estimator/backend/feature_selection.h"

#include <algorithm>
#include <optional>
#include <utility>

#include <Eigen/Cholesky>

namespace evio::estimator {

namespace {
/// Observed in clone `clone_id`.
bool isObservedIn(const FeatureTrack& track, std::int64_t clone_id) {
  return !track.observations.empty() && track.observations.back().clone_id == clone_id;
}
/// In the measurement set of clone `clone_id` (observed or not informative).
bool isLive(const FeatureTrack& track, std::int64_t clone_id) {
  return isObservedIn(track, clone_id) || track.seen_clone_id == clone_id;
}
}  // namespace

Mat2 whiteningFor(const Mat2& cov_z, double sigma_z) {
  if (!cov_z.allFinite() || !(cov_z.trace() > 0.0)) return Mat2::Identity();
  const Eigen::LLT<Mat2> llt(0.5 * (cov_z + cov_z.transpose()));
  if (llt.info() != Eigen::Success) return Mat2::Identity();
  const Mat2 L = llt.matrixL();
  if (!(L(0, 0) > 0.0) || !(L(1, 1) > 0.0)) return Mat2::Identity();
  const Mat2 W = sigma_z * L.inverse();
  return W.allFinite() ? W : Mat2::Identity();
}

std::vector<FeatureObservation> undistortObservations(const MeasurementSet& set, const Camera& camera,
                                                      double sigma_z, BackendStats* stats) {
  const Vec4 k = camera.intrinsics();
  const Mat2 K_inv = Vec2(1.0 / k(0), 1.0 / k(1)).asDiagonal();
  std::vector<FeatureObservation> out;
  out.reserve(set.features.size());
  std::unordered_set<FeatureId> seen;
  for (const FeatureMeasurement& m : set.features) {
    if (!seen.insert(m.id).second) continue;
    Vec3 bearing;
    if (!camera.unproject(m.uv, &bearing) || !(bearing.z() > 1e-6)) {
      ++stats->features_undistort_failed;
      continue;
    }
    const bool stated = m.cov_px != Mat2::Zero();
    out.push_back({m.id, bearing.head<2>() / bearing.z(),
                   stated ? whiteningFor(K_inv * m.cov_px * K_inv, sigma_z) : Mat2::Identity(), m.informative,
                   m.error_time_s});
  }
  return out;
}

void extendTracks(const std::vector<FeatureObservation>& observations, const FilterState& state,
                  std::int64_t clone_id, TrackMap* tracks) {
  for (const FeatureObservation& o : observations) {
    if (state.findFeature(o.id) >= 0) continue;
    if (!o.informative && tracks->count(o.id) == 0) continue;  // a track starts at an informative position
    FeatureTrack& track = (*tracks)[o.id];
    track.id = o.id;
    track.seen_clone_id = clone_id;
    if (o.informative) track.observations.push_back({clone_id, o.z, o.whiten});
  }
}

std::vector<FeatureId> chooseSlamCandidates(const TrackMap& tracks, std::int64_t clone_id, int free_slots,
                                            int min_length) {
  return chooseSlamCandidates(tracks, FilterState{}, clone_id, free_slots,
                              SlamEligibility{.min_length = min_length, .min_span_ns = 0});
}

std::vector<FeatureId> chooseSlamCandidates(const TrackMap& tracks, const FilterState& state, std::int64_t clone_id,
                                            int free_slots, const SlamEligibility& rule) {
  std::vector<FeatureId> out;
  if (free_slots <= 0) return out;
  // Every observation's clone is in the window (marginalizeClone drops the
  // observations of the clone it removes); a track whose clone is not found
  // is not admitted by the span.
  const auto cloneTime = [&state](std::int64_t id) -> std::optional<TimeNs> {
    for (const auto& c : state.clones)
      if (c.id == id) return c.t_ns;
    return std::nullopt;
  };
  const std::optional<TimeNs> newest = rule.min_span_ns > 0 ? cloneTime(clone_id) : std::nullopt;
  const auto spansEnough = [&](const FeatureTrack& track) {
    if (!newest || static_cast<int>(track.observations.size()) < rule.span_min_length) return false;
    const std::optional<TimeNs> first = cloneTime(track.observations.front().clone_id);
    return first && *newest - *first >= rule.min_span_ns;
  };
  std::vector<std::pair<std::size_t, FeatureId>> eligible;  // (length, id)
  for (const auto& [id, track] : tracks)
    if (isObservedIn(track, clone_id) &&
        (static_cast<int>(track.observations.size()) >= rule.min_length || spansEnough(track)))
      eligible.emplace_back(track.observations.size(), id);
  std::sort(eligible.begin(), eligible.end(),
            [](const auto& a, const auto& b) { return a.first != b.first ? a.first > b.first : a.second < b.second; });
  for (int k = 0; k < free_slots && k < static_cast<int>(eligible.size()); ++k)
    out.push_back(eligible[static_cast<std::size_t>(k)].second);
  return out;
}

MsckfChoice chooseMsckfTracks(const TrackMap& tracks, std::int64_t newest_clone_id, std::int64_t oldest_clone_id,
                              bool sliding, const std::unordered_set<FeatureId>& slam_candidates, int min_length,
                              bool use_lost_tracks) {
  MsckfChoice out;
  for (const auto& [id, track] : tracks) {
    const int length = static_cast<int>(track.observations.size());
    if (!isLive(track, newest_clone_id)) {
      if (use_lost_tracks && length >= min_length) out.update.push_back(id);
      out.erase.push_back(id);
    } else if (sliding && slam_candidates.count(id) == 0 && track.observations.front().clone_id == oldest_clone_id &&
               length >= min_length) {
      out.update.push_back(id);
    }
  }
  return out;
}

}  // namespace evio::estimator

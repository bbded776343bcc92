#pragma once
/// @file feature_selection.h
/// The bookkeeping steps of one visual update (backend.h, steps 1–3 and 5),
/// as plain functions of the tracks so that each is tested on its own:
/// which observations the set gives, which tracks they extend, which tracks
/// become SLAM features and which are used as MSCKF features.

#include <cstdint>
#include <map>
#include <unordered_set>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/estimator/backend/backend_status.h"
#include "evio/estimator/backend/feature_track.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

/// A feature observed in the newest clone: undistorted normalised coordinates z.
struct FeatureObservation {
  FeatureId id = 0;
  Vec2 z = Vec2::Zero();
  Mat2 whiten = Mat2::Identity();  ///< as TrackObservation::whiten
  /// FeatureMeasurement::informative: false keeps the feature alive (SLAM
  /// feature not marginalised, track not lost) without an observation.
  bool informative = true;
  double error_time_s = 0.0;  ///< FeatureMeasurement::error_time_s
};

using TrackMap = std::map<FeatureId, FeatureTrack>;

/// The set's features as normalised observations z = (x/z, y/z) of the
/// unprojected bearing, in the set's order; a repeated id keeps its first
/// measurement; a pixel that does not unproject in front of the camera
/// (bearing z ≤ 1e-6) is dropped and counted in features_undistort_failed.
/// A stated pixel covariance Σ_px becomes Σ_z = K⁻¹ Σ_px K⁻ᵀ, K = diag(fx, fy)
/// (the intrinsics, as σ_img_px / f for σ_z), and the whitening W = σ_z L⁻¹
/// with L Lᵀ = Σ_z; a covariance that is not positive definite or finite
/// counts as not stated.
std::vector<FeatureObservation> undistortObservations(const MeasurementSet& set, const Camera& camera,
                                                      double sigma_z, BackendStats* stats);

/// The whitening W = σ_z L⁻¹ (L Lᵀ = Σ_z) of a normalised-coordinate
/// covariance; identity when Σ_z is not finite and positive definite.
Mat2 whiteningFor(const Mat2& cov_z, double sigma_z);

/// Appends clone `clone_id` to the track of every informative observation
/// that is not a SLAM feature of `state` (a new id starts a track), and marks
/// every observed track seen in clone `clone_id` (alive).
void extendTracks(const std::vector<FeatureObservation>& observations, const FilterState& state,
                  std::int64_t clone_id, TrackMap* tracks);

/// The tracks that fill `free_slots` free SLAM slots: ones with an
/// observation in clone `clone_id` with at least `min_length` observations, longest first,
/// ties by the smaller id.
std::vector<FeatureId> chooseSlamCandidates(const TrackMap& tracks, std::int64_t clone_id, int free_slots,
                                            int min_length);

/// Which tracks may become SLAM: `min_length` observations, or, when
/// `min_span_ns` > 0, at least `span_min_length` observations whose first
/// and newest clones (times from `state`) lie `min_span_ns` or more apart:
/// an event tracker reports a slowly moving feature at few updates, so its
/// track can span the time ten frames take with fewer observations.
struct SlamEligibility {
  int min_length = 10;
  TimeNs min_span_ns = 0;
  int span_min_length = 3;
};

/// chooseSlamCandidates with the span rule of `rule`.
std::vector<FeatureId> chooseSlamCandidates(const TrackMap& tracks, const FilterState& state, std::int64_t clone_id,
                                            int free_slots, const SlamEligibility& rule);

struct MsckfChoice {
  std::vector<FeatureId> update;  ///< tracks to use as MSCKF features, in id order
  std::vector<FeatureId> erase;   ///< lost tracks (not seen in the newest clone), in id order
};

/// MSCKF features of this update: tracks about to lose their oldest
/// observation as the window slides (`sliding`: first observation in clone
/// `oldest_clone_id`; not chosen as SLAM candidates), and lost tracks when
/// `use_lost_tracks`; both with at least `min_length` observations. Lost
/// tracks are erased whether used or not.
MsckfChoice chooseMsckfTracks(const TrackMap& tracks, std::int64_t newest_clone_id, std::int64_t oldest_clone_id,
                              bool sliding, const std::unordered_set<FeatureId>& slam_candidates, int min_length,
                              bool use_lost_tracks);

}  // namespace evio::estimator

#pragma once
/// @file feature_track.h
/// The observations of one (not yet SLAM) feature track in the sliding window.

#include <cstdint>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

/// Observation z (undistorted normalised image coordinates) of a feature in the
/// clone with id clone_id.
struct TrackObservation {
  std::int64_t clone_id = 0;
  Vec2 z = Vec2::Zero();
  /// Whitening to the backend's σ_z: W with W Σ_z Wᵀ = σ_z² I for the
  /// observation's covariance Σ_z, so W (z − ẑ) has covariance σ_z² I and
  /// the updaters keep one σ_z (docs/algorithms.md#measurement-covariance).
  /// Identity when the tracker stated no covariance (Σ_z = σ_z² I).
  Mat2 whiten = Mat2::Identity();
};

struct FeatureTrack {
  FeatureId id = 0;
  std::vector<TrackObservation> observations;  ///< oldest first, one per clone at most
  /// The newest clone whose measurement set held the feature, informative or
  /// not (−1: only its observations count).
  std::int64_t seen_clone_id = -1;
};

}  // namespace evio::estimator

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
};

struct FeatureTrack {
  FeatureId id = 0;
  std::vector<TrackObservation> observations;  ///< oldest first, one per clone at most
};

}  // namespace evio::estimator

#pragma once
/// @file track_point.h
/// What a feature tracker reports: one sample of one feature track.

#include <cstdint>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/time.h"

namespace evio::estimator {

/// Identifier of a feature track, unique within one tracker run (never reused).
using FeatureId = std::int64_t;

/// Where a track point stands in the life of its track.
enum class TrackStatus : std::uint8_t {
  kNew,      ///< first point of a new track
  kTracked,  ///< a further point of a live track
  kLost,     ///< the track ended; uv/t_ns repeat its last good point
};

/// One sample of a feature track.
struct TrackPoint {
  FeatureId feature_id = 0;
  TimeNs t_ns = 0;                ///< time of the sample (EKLT: middle of the event batch)
  Vec2 uv = Vec2::Zero();         ///< position in px, distorted image coordinates (camera_common.h)
  double quality = 1.0;           ///< tracking quality in [0, 1] (EKLT: 1 − cost/2; KLT: 1)
  TrackStatus status = TrackStatus::kTracked;
};

using TrackPoints = std::vector<TrackPoint>;

}  // namespace evio::estimator

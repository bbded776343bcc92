#pragma once
/// Feature tracks for backend tests: a track observed in given clones (zero
/// observations), and a TrackMap from a list of tracks.

#include <utility>
#include <vector>

#include "evio/estimator/backend/feature_selection.h"  // FeatureTrack, TrackMap

namespace evio::test {

inline estimator::FeatureTrack track(estimator::FeatureId id, std::vector<std::int64_t> clone_ids) {
  estimator::FeatureTrack t;
  t.id = id;
  for (const std::int64_t c : clone_ids) t.observations.push_back({c, Vec2::Zero()});
  return t;
}

inline estimator::TrackMap tracksOf(std::vector<estimator::FeatureTrack> list) {
  estimator::TrackMap out;
  for (estimator::FeatureTrack& t : list) out[t.id] = std::move(t);
  return out;
}

}  // namespace evio::test

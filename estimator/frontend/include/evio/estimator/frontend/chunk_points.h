#pragma once
/// @file chunk_points.h
/// Track points of one event chunk from trackers whose features are tracked
/// in parallel parts (eklt_tracker.h, haste_tracker.h): each point carries
/// what orders it in a single-thread run (the index of the event that
/// produced it, then the feature slot, visited low to high for an event), so
/// the parts' points merge into the single-thread order.

#include <cstddef>
#include <memory>
#include <vector>

#include "evio/estimator/measurements.h"

namespace evio::estimator {

struct ChunkPoint {
  std::size_t event;  ///< index of the event in the chunk's EventArray
  int slot;           ///< the feature's slot
  TrackPoint point;
};

/// Appends the points of every part (each in (event, slot) order) to `out`
/// in (event, slot) order, and clears the parts. At most 256 parts.
void mergeChunkPoints(const std::vector<std::vector<ChunkPoint>*>& parts, TrackPoints& out);

/// The same for events that arrived as consecutive chunks [0, e0), [e0, e1), …
/// (`chunk_ends`, non-decreasing; every point's event below its last entry):
/// also appends to `point_ends`, for every chunk, out.size() after its points
/// (a point belongs to the chunk of the event that produced it).
void mergeChunkPoints(const std::vector<std::vector<ChunkPoint>*>& parts, const std::vector<std::size_t>& chunk_ends,
                      TrackPoints& out, std::vector<std::size_t>& point_ends);

}  // namespace evio::estimator

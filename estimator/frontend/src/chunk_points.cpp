#include "evio/estimator/frontend/chunk_points.h"

#include <algorithm>
#include <limits>

#include "evio/core/error.h"

namespace evio::estimator {

namespace {

/// Calls visit(point) for the parts' points in (event, slot) order (each
/// part is in that order already), then clears the parts.
template <class Visit>
void visitInOrderAndClear(const std::vector<std::vector<ChunkPoint>*>& parts, Visit visit) {
  require(parts.size() <= 256, "mergeChunkPoints: at most 256 parts");
  if (parts.size() == 1) {
    for (const ChunkPoint& c : *parts.front()) visit(c);
    parts.front()->clear();
    return;
  }
  std::size_t heads[256] = {};
  while (true) {
    const ChunkPoint* best = nullptr;
    std::size_t best_part = 0;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      const std::vector<ChunkPoint>& pts = *parts[k];
      if (heads[k] == pts.size()) continue;
      const ChunkPoint& c = pts[heads[k]];
      if (!best || c.event < best->event || (c.event == best->event && c.slot < best->slot)) {
        best = &c;
        best_part = k;
      }
    }
    if (!best) break;
    visit(*best);
    ++heads[best_part];
  }
  for (std::vector<ChunkPoint>* p : parts) p->clear();
}

}  // namespace

void mergeChunkPoints(const std::vector<std::vector<ChunkPoint>*>& parts, TrackPoints& out) {
  visitInOrderAndClear(parts, [&out](const ChunkPoint& c) { out.push_back(c.point); });
}

void mergeChunkPoints(const std::vector<std::vector<ChunkPoint>*>& parts, const std::vector<std::size_t>& chunk_ends,
                      TrackPoints& out, std::vector<std::size_t>& point_ends) {
  require(std::is_sorted(chunk_ends.begin(), chunk_ends.end()), "mergeChunkPoints: chunk ends must not decrease");
  for (const std::vector<ChunkPoint>* p : parts)
    require(p->empty() || (!chunk_ends.empty() && p->back().event < chunk_ends.back()),
            "mergeChunkPoints: a point after the last chunk");
  std::size_t chunk = 0;
  // Closes the chunks that end at or before `event` (all of them for SIZE_MAX).
  const auto closeChunksBefore = [&](std::size_t event) {
    while (chunk < chunk_ends.size() && chunk_ends[chunk] <= event) {
      point_ends.push_back(out.size());
      ++chunk;
    }
  };
  visitInOrderAndClear(parts, [&](const ChunkPoint& c) {
    closeChunksBefore(c.event);
    out.push_back(c.point);
  });
  closeChunksBefore(std::numeric_limits<std::size_t>::max());
}

}  // namespace evio::estimator

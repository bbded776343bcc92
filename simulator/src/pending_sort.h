#pragma once
// Internal to evio::simulator: the order in which the event camera emits
// what its pixels produced (event_camera.cpp, appendSorted).

#include <cstdint>
#include <vector>

#include "evio/simulator/event_camera.h"

namespace evio::simulator {

/// Sorts pending events by (t, pixel, label, polarity). When (t − t_min,
/// pixel, label, polarity) packs into 64 bits, an LSD radix sort on the
/// packed keys (8-bit digits, only the passes the key width needs); else a
/// comparison sort. Both give the same order. `keys` and `scratch` are
/// reused buffers (no allocation once they are large enough).
void sortPending(std::vector<EventCamera::Pending>::iterator begin, std::vector<EventCamera::Pending>::iterator end,
                 std::size_t pixel_count, std::vector<std::uint64_t>* keys, std::vector<std::uint64_t>* scratch);

}  // namespace evio::simulator

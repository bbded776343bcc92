#pragma once
/// @file background_activity_filter.h
/// The DAVIS background-activity (BA) filter: the correlation filter the
/// DAVIS FPGA logic applies to the DVS event stream before it leaves the
/// camera, enabled by the recording driver (libcaer and the rpg_dvs_ros
/// driver of the Event-Camera Dataset: DAVIS_CONFIG_DVS_FILTER_BACKGROUND_ACTIVITY
/// on, its time 80 blocks of 250 µs = 20 ms).
///
/// Rule (the neighbour-stamping form of Delbruck's BackgroundActivityFilter,
/// which the logic implements): a memory holds one time stamp per pixel.
/// Every incoming event at (x, y, t), passed or not,
///   1. passes iff its own stamp s(x, y) satisfies t − s(x, y) ≤ T,
///   2. then writes t into the stamps of its 8 neighbours (not its own).
/// So an event passes only if one of its 8 neighbours fired within T before
/// it; an isolated event (no neighbour within T) is dropped, and the first
/// event of a pair of neighbours is dropped while the second passes. Events
/// must arrive in time order; the result depends only on that order, so it
/// does not depend on thread counts. Memory: 8 bytes per pixel.

#include <cstdint>
#include <vector>

#include "evio/core/time.h"

namespace evio::simulator {

class BackgroundActivityFilter {
 public:
  /// A filter for width × height pixels with support window T = window_ns (> 0).
  BackgroundActivityFilter(int width, int height, TimeNs window_ns);

  /// Applies the rule to one event (times non-decreasing); true if it passes.
  bool pass(std::uint16_t x, std::uint16_t y, TimeNs t_ns);

  TimeNs window() const { return window_ns_; }

 private:
  int width_ = 0, height_ = 0;
  TimeNs window_ns_ = 0;
  std::vector<TimeNs> stamp_;  ///< last neighbour event time per pixel (y·width + x)
};

}  // namespace evio::simulator

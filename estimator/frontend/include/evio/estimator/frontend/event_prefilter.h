#pragma once
/// @file event_prefilter.h
/// Event-rate reduction before tracking, the speed-up strategies of
/// Mahlknecht et al. 2022 (Speedup Strategies; docs/algorithms.md#event-pre-filters): random filtering (RF), which keeps
/// on average every r-th event, and refractory-period filtering (RPF), which
/// drops an event that follows the previous *kept* event of the same pixel by
/// less than τ.

#include <cstdint>
#include <vector>

#include "evio/core/event.h"
#include "evio/core/options.h"
#include "evio/core/random_stream.h"

namespace evio::estimator {

struct EventPrefilterOptions {
  /// RF: keep each event with probability 1/r (1 keeps all).
  int random_keep_one_in = 1;
  /// Seed of the RF random stream (stream name "event_prefilter").
  std::uint64_t random_seed = 1;
  /// RPF: refractory period τ in seconds (0 disables).
  double refractory_period_s = 0.0;

  template <class V>
  void fields(V& v) {
    v("random_keep_one_in", random_keep_one_in, "random filtering: keep each event with probability 1/r");
    v("random_seed", random_seed, "seed of the random-filter stream");
    v("refractory_period_s", refractory_period_s, "per-pixel refractory period in s (0: off)");
  }
  void validate() const {
    requireField(random_keep_one_in >= 1, "random_keep_one_in", "must be >= 1");
    requireNonNegative("refractory_period_s", refractory_period_s);
  }
  /// True when neither filter is active.
  bool passThrough() const { return random_keep_one_in == 1 && refractory_period_s == 0.0; }
};

class EventPrefilter {
 public:
  /// `width`×`height` is the sensor size (events outside are an error).
  EventPrefilter(const EventPrefilterOptions& options, int width, int height);

  /// Replaces `out` with the kept events of in[begin, end). `out` keeps its
  /// capacity between calls, so steady-state filtering allocates nothing.
  void filter(const EventArray& in, std::size_t begin, std::size_t end, EventArray* out);

  std::uint64_t numSeen() const { return seen_; }
  std::uint64_t numKept() const { return kept_; }

 private:
  EventPrefilterOptions options_;
  int width_;
  int height_;
  TimeNs refractory_ns_;
  RandomStream random_;
  std::vector<TimeNs> last_kept_ns_;  // per pixel; empty when RPF is off
  std::uint64_t seen_ = 0;
  std::uint64_t kept_ = 0;
};

}  // namespace evio::estimator

#pragma once
/// @file sequence_stats.h
/// `evio stats`: the statistics of a sequence folder's events and frames
/// that say how much it looks like a real DAVIS (issue 17), for recorded
/// and simulated folders alike. Streaming: events are read in chunks through
/// core/io, frames one at a time; memory is per-pixel state plus fixed-size
/// histograms and the rate series (one number per window), not the events.
///
/// Times are those of the files (int64 ns inside). A duration D is
/// t_last − t_first of the events. Quantiles are nearest-rank
/// (stats_quantiles.h), so a sorted list in Python reproduces them.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/event.h"
#include "evio/core/time.h"
#include "evio/experiments/json_value.h"
#include "evio/experiments/sequence_info.h"
#include "evio/experiments/stats_quantiles.h"

namespace evio::experiments {

struct SequenceStatsOptions {
  double rate_window_s = 0.010;       ///< width of the event-rate windows, s
  double burst_gap_s = 0.005;         ///< same pixel and polarity: a gap longer than this starts a new burst, s
  double isolation_window_s = 0.010;  ///< Δt of the isolated-event test, s
  int width_px = 0;                   ///< sensor width; 0: from the folder (as `evio info` finds it)
  int height_px = 0;                  ///< sensor height; 0: from the folder

  template <class V>
  void fields(V& v) {
    v("rate_window_s", rate_window_s, "width of the event-rate windows, s");
    v("burst_gap_s", burst_gap_s, "a same-pixel same-polarity gap longer than this starts a new burst, s");
    v("isolation_window_s", isolation_window_s, "time half-window of the isolated-event test, s");
    v("width_px", width_px, "sensor width, px (0: from the folder)");
    v("height_px", height_px, "sensor height, px (0: from the folder)");
  }
  void validate() const;
};

/// Statistics of the event stream. Absent (present = false) without events.
struct EventStreamStats {
  bool present = false;
  std::string file;             ///< events.h5 or events.txt
  std::uint64_t count = 0;
  std::uint64_t on_count = 0;   ///< polarity 1
  TimeNs t_first_ns = 0, t_last_ns = 0;
  double durationS() const { return nsToSeconds(t_last_ns - t_first_ns); }
  double meanRateHz() const;    ///< count / D, events/s (0 when D = 0)
  double onFraction() const;    ///< on_count / count

  /// Events in the whole windows [t_first + k·w, t_first + (k+1)·w),
  /// k = 0 … floor(D / w) − 1 (w = rate_window_s; the partial last window is
  /// left out), and the quantiles of count / w over them, events/s.
  std::vector<std::uint64_t> window_counts;
  Quantiles window_rate_hz;

  /// Same-pixel same-polarity intervals: t_k+1 − t_k of consecutive events
  /// of one pixel and one polarity (other pixels and the other polarity do
  /// not interrupt), s. Quantiles to 1 µs (DurationHistogram), min exact.
  std::uint64_t interval_count = 0;
  Quantiles interval_s;
  double interval_under_1ms_fraction = 0.0;  ///< intervals < 1 ms / all intervals

  /// Events per edge crossing, a proxy from the event stream alone: per
  /// pixel and polarity, consecutive events whose interval is ≤ burst_gap_s
  /// form one burst; a longer interval (and the end of the stream) closes
  /// it. Quantiles of events per burst. It equals events per crossing only
  /// when crossings of one pixel are more than burst_gap_s apart and no
  /// crossing pauses longer than that; there is no image-speed figure
  /// (truth/ has no per-event flow to make one exactly).
  std::uint64_t burst_count = 0;
  Quantiles events_per_burst;

  /// Isolated events: no other event, of either polarity, at the same pixel
  /// or its 8 neighbours with |t' − t| ≤ isolation_window_s. Rate =
  /// isolated / (width · height · D), Hz per pixel.
  std::uint64_t isolated_count = 0;
  double isolated_rate_hz_per_pixel = 0.0;

  /// Quantiles of the event count of each of the width · height pixels
  /// (pixels without events included).
  Quantiles pixel_count;
};

/// Statistics of the frames (images.txt). Absent (present = false) without.
struct FrameStreamStats {
  bool present = false;
  std::uint64_t count = 0;
  int width = 0, height = 0;        ///< of the first frame (all must match)
  TimeNs t_first_ns = 0, t_last_ns = 0;
  double rateHz() const;            ///< (count − 1) / (t_last − t_first), Hz

  /// The exposure, s, only when the folder records it exactly; nullopt
  /// (unknown) otherwise, with `exposure_note` saying what is recorded. The
  /// simulator's sensors.yaml holds the configured exposure_s and
  /// auto_exposure of the frame camera, not the exposure each frame used
  /// (auto-exposure, or the first exposure metered), so it is unknown there
  /// too; ECD folders record none.
  std::optional<double> exposure_s;
  std::string exposure_note;

  std::array<std::uint64_t, 256> histogram{};  ///< pixels per DN, all frames
  double brightness_mean_dn = 0.0;             ///< mean DN over all pixels of all frames
  double fraction_at_0 = 0.0;                  ///< pixels at DN 0 / all pixels
  double fraction_at_255 = 0.0;                ///< pixels at DN 255 / all pixels
  /// Per frame: its largest DN (the white level where the frame clips) and
  /// the fraction of its pixels at that DN; the quantiles of the largest DN
  /// over frames and the mean of the fraction over frames.
  Quantiles max_dn;
  double fraction_at_max = 0.0;
  /// Per frame: the white level, the largest DN held by at least 0.5 % of
  /// the frame's pixels (a real APS clips at a spread of DN, fixed-pattern
  /// noise), and the fraction of pixels at or above white level − 10 DN;
  /// the quantiles of the white level over frames and the mean fraction.
  Quantiles white_level_dn;
  double fraction_near_white = 0.0;
  /// Sharpness: variance of the Laplacian, DN², per frame over the interior
  /// pixels (1 ≤ x ≤ W−2, 1 ≤ y ≤ H−2) with L = I(x−1,y) + I(x+1,y) +
  /// I(x,y−1) + I(x,y+1) − 4·I(x,y), population variance; mean over frames.
  double laplacian_variance_dn2 = 0.0;
};

struct SequenceStats {
  std::string folder;
  int width = 0, height = 0;       ///< sensor size used for per-pixel figures
  std::string resolution_source;
  SequenceStatsOptions options;
  EventStreamStats events;
  FrameStreamStats frames;
};

/// Measures `folder`. Throws evio::Error if the folder does not exist, has
/// neither events nor frames (saying which files it looked for), or a file
/// is malformed (file:line from core/io).
SequenceStats computeSequenceStats(const std::string& folder, const SequenceStatsOptions& options = {},
                                   const ProgressCallback& progress = {});

/// Event statistics of a stream fed in time order (the engine of
/// computeSequenceStats, public for tests): per-pixel state for width · height.
class EventStatsAccumulator {
 public:
  EventStatsAccumulator(int width, int height, const SequenceStatsOptions& options);
  void add(const EventArray& events);
  EventStreamStats finish();

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

/// JSON (every figure, the rate series and the 256-bin histogram) and a
/// short plain-text table.
JsonValue sequenceStatsJson(const SequenceStats& stats);
std::string formatSequenceStats(const SequenceStats& stats);

}  // namespace evio::experiments

#pragma once
/// @file real_time_factor.h
/// Real-time factor (docs/evaluation.md#real-time-factor) from the estimator's timing.txt
/// (core/io/timing_txt.h): processing time over data time, sampled on a grid
/// of data time starting at the first timing row (the estimator writes it on
/// initialisation). Cumulative processing time P(t) and event count N(t) are
/// interpolated linearly at the grid points g_m = t_first + m·Δ; for each
/// whole grid interval
///   RTF_m = (P(g_{m+1}) − P(g_m)) / Δ,   event rate_m = (N(g_{m+1}) − N(g_m)) / Δ.
/// Reported: median and maximum of RTF_m, and the overall ratio
/// (P_last − P_first) / (t_last − t_first). RTF < 1 is faster than real time.

#include <vector>

#include "evio/core/io/timing_txt.h"

namespace evio::experiments {

struct RtfSample {
  double t_s = 0.0;            ///< start of the grid interval, data time, s
  double rtf = 0.0;
  double event_rate_hz = 0.0;  ///< events per second of data time in the interval
};

struct RtfMetrics {
  bool available = false;  ///< at least one whole grid interval
  double grid_s = 0.2;
  double median = 0.0;
  double max = 0.0;
  double overall = 0.0;
  double mean_event_rate_hz = 0.0;  ///< over the timed span
  std::vector<RtfSample> samples;
};

/// RTF of `timing` (validated rows, increasing t) on a grid of `grid_s` (> 0).
RtfMetrics realTimeFactor(const std::vector<io::TimingSample>& timing, double grid_s);

}  // namespace evio::experiments

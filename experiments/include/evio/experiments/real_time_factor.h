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
///
/// Tracked features (timing.txt's 4th column, when the file has it): F_m is
/// the mean of the features column over the rows with g_m < t <= g_{m+1};
/// an interval without a row takes the count at its end (that of the last
/// row at or before g_{m+1}: the column is a step function of t). The RTF per
/// tracked feature is RTF_m / F_m, undefined (NaN) where F_m = 0.

#include <limits>
#include <vector>

#include "evio/core/io/timing_txt.h"

namespace evio::experiments {

struct RtfSample {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  double t_s = 0.0;            ///< start of the grid interval, data time, s
  double rtf = 0.0;
  double event_rate_hz = 0.0;  ///< events per second of data time in the interval
  double features = kNaN;         ///< F_m; NaN when timing.txt has no features column
  double rtf_per_feature = kNaN;  ///< RTF_m / F_m; NaN when F_m is unknown or 0
};

struct RtfMetrics {
  bool available = false;  ///< at least one whole grid interval
  double grid_s = 0.2;
  double median = 0.0;
  double max = 0.0;
  double overall = 0.0;
  double mean_event_rate_hz = 0.0;  ///< over the timed span
  bool features_known = false;      ///< timing.txt has the features column
  double median_features = RtfSample::kNaN;     ///< median of F_m (features_known)
  double median_per_feature = RtfSample::kNaN;  ///< median of RTF_m / F_m over the intervals with F_m > 0
  std::vector<RtfSample> samples;
};

/// RTF of `timing` (validated rows, increasing t) on a grid of `grid_s` (> 0).
RtfMetrics realTimeFactor(const std::vector<io::TimingSample>& timing, double grid_s);

}  // namespace evio::experiments

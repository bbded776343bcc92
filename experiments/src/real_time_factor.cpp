#include "evio/experiments/real_time_factor.h"

#include <algorithm>

#include "evio/core/error.h"
#include "evio/experiments/trajectory_errors.h"

namespace evio::experiments {

namespace {

/// Linear interpolation of (processing_s, events) at t (inside the span).
std::pair<double, double> at(const std::vector<io::TimingSample>& timing, TimeNs t_ns) {
  const auto it = std::lower_bound(timing.begin(), timing.end(), t_ns,
                                   [](const io::TimingSample& s, TimeNs t) { return s.t_ns < t; });
  if (it == timing.begin()) return {it->processing_s, static_cast<double>(it->events)};
  if (it == timing.end()) return {timing.back().processing_s, static_cast<double>(timing.back().events)};
  const auto& a = *(it - 1);
  const auto& b = *it;
  const double s = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return {a.processing_s + s * (b.processing_s - a.processing_s),
          static_cast<double>(a.events) + s * static_cast<double>(b.events - a.events)};
}

/// F_m of (g0, g1] (real_time_factor.h): the mean features of the rows with
/// g0 < t <= g1, else the features of the last row at or before g1.
double intervalFeatures(const std::vector<io::TimingSample>& timing, TimeNs g0, TimeNs g1) {
  const auto by_t = [](const io::TimingSample& s, TimeNs t) { return s.t_ns <= t; };
  const auto first = std::lower_bound(timing.begin(), timing.end(), g0, by_t);  // first row with t > g0
  const auto end = std::lower_bound(first, timing.end(), g1, by_t);            // first row with t > g1
  if (first == end) return end == timing.begin() ? 0.0 : static_cast<double>(*(end - 1)->features);
  double sum = 0.0;
  for (auto it = first; it != end; ++it) sum += static_cast<double>(*it->features);
  return sum / static_cast<double>(end - first);
}

bool hasFeatures(const std::vector<io::TimingSample>& timing) {
  return std::all_of(timing.begin(), timing.end(), [](const io::TimingSample& s) { return s.features.has_value(); });
}

/// Fills F_m, RTF_m / F_m and their medians.
void addFeatures(const std::vector<io::TimingSample>& timing, TimeNs step, RtfMetrics& m) {
  m.features_known = true;
  std::vector<double> features, per_feature;
  TimeNs g = timing.front().t_ns;
  for (RtfSample& s : m.samples) {
    s.features = intervalFeatures(timing, g, g + step);
    if (s.features > 0.0) {
      s.rtf_per_feature = s.rtf / s.features;
      per_feature.push_back(s.rtf_per_feature);
    }
    features.push_back(s.features);
    g += step;
  }
  m.median_features = errorStats(std::move(features)).median;
  if (!per_feature.empty()) m.median_per_feature = errorStats(std::move(per_feature)).median;
}

}  // namespace

RtfMetrics realTimeFactor(const std::vector<io::TimingSample>& timing, double grid_s) {
  require(grid_s > 0.0, "realTimeFactor: grid_s must be > 0");
  RtfMetrics m;
  m.grid_s = grid_s;
  if (timing.size() < 2) return m;
  const TimeNs step = secondsToNs(grid_s);
  const TimeNs t0 = timing.front().t_ns;
  const TimeNs t1 = timing.back().t_ns;
  auto prev = at(timing, t0);
  for (TimeNs g = t0; g + step <= t1; g += step) {
    const auto next = at(timing, g + step);
    m.samples.push_back({nsToSeconds(g), (next.first - prev.first) / grid_s, (next.second - prev.second) / grid_s});
    prev = next;
  }
  const double span_s = nsToSeconds(t1 - t0);
  m.overall = (timing.back().processing_s - timing.front().processing_s) / span_s;
  m.mean_event_rate_hz = static_cast<double>(timing.back().events - timing.front().events) / span_s;
  if (m.samples.empty()) return m;
  m.available = true;
  std::vector<double> rtf;
  rtf.reserve(m.samples.size());
  for (const auto& s : m.samples) rtf.push_back(s.rtf);
  const ErrorStats stats = errorStats(std::move(rtf));
  m.median = stats.median;
  m.max = stats.max;
  if (hasFeatures(timing)) addFeatures(timing, step, m);
  return m;
}

}  // namespace evio::experiments

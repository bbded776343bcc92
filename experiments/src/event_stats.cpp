// EventStatsAccumulator: the event half of `evio stats` (sequence_stats.h).
#include <algorithm>
#include <limits>
#include <string>

#include "evio/core/error.h"
#include "evio/experiments/sequence_stats.h"

namespace evio::experiments {

namespace {
constexpr TimeNs kNever = std::numeric_limits<TimeNs>::min();
}  // namespace

struct EventStatsAccumulator::Impl {
  int width, height;
  TimeNs window_ns, burst_gap_ns, isolation_ns;
  EventStreamStats s;
  // Per pixel and polarity (index 2·pixel + p): last event time, events in the open burst.
  std::vector<TimeNs> last_same;
  std::vector<std::uint32_t> burst_events;
  // Per pixel: last event time of either polarity, whether that event has
  // had no neighbour so far (a candidate isolated event), event count.
  std::vector<TimeNs> last_any;
  std::vector<std::uint8_t> candidate;
  std::vector<std::uint32_t> pixel_events;
  DurationHistogram intervals;
  IntegerHistogram bursts;

  void addOne(TimeNs t, int x, int y, bool on);
};

void EventStatsAccumulator::Impl::addOne(TimeNs t, int x, int y, bool on) {
  if (x >= width || y >= height)
    throw Error("event at pixel (" + std::to_string(x) + ", " + std::to_string(y) + ") outside the sensor " +
                std::to_string(width) + "x" + std::to_string(height));
  if (s.count == 0) s.t_first_ns = t;
  s.t_last_ns = t;
  ++s.count;
  s.on_count += on ? 1 : 0;
  const auto window = static_cast<std::size_t>((t - s.t_first_ns) / window_ns);
  // The rate series grows with the time span: bound it (a stray timestamp
  // far in the future must be an error, not gigabytes of empty windows).
  constexpr std::size_t kMaxWindows = 100'000'000;
  if (window >= kMaxWindows)
    throw Error("events: " + std::to_string(window) + " rate windows of " + std::to_string(window_ns) +
                " ns from the first event at an event of " + std::to_string(nsToSeconds(t)) +
                " s; give a wider rate_window_s or check the timestamps");
  if (window >= s.window_counts.size()) s.window_counts.resize(window + 1, 0);
  ++s.window_counts[window];

  const std::size_t pixel = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
  ++pixel_events[pixel];
  const std::size_t same = 2 * pixel + (on ? 1 : 0);
  if (last_same[same] != kNever) {
    const TimeNs dt = t - last_same[same];
    intervals.add(dt);
    if (dt > burst_gap_ns) {
      bursts.add(burst_events[same]);
      burst_events[same] = 0;
    }
  }
  ++burst_events[same];
  last_same[same] = t;

  // Isolation: the latest event of each pixel of the 3x3 block decides the past side;
  // a later neighbour clears an earlier candidate (the future side).
  bool alone = true;
  for (int yy = std::max(0, y - 1); yy <= std::min(height - 1, y + 1); ++yy)
    for (int xx = std::max(0, x - 1); xx <= std::min(width - 1, x + 1); ++xx) {
      const std::size_t q = static_cast<std::size_t>(yy) * static_cast<std::size_t>(width) + static_cast<std::size_t>(xx);
      if (last_any[q] == kNever || t - last_any[q] > isolation_ns) continue;
      alone = false;
      candidate[q] = 0;
    }
  if (candidate[pixel]) ++s.isolated_count;  // its window has passed with no neighbour
  candidate[pixel] = alone ? 1 : 0;
  last_any[pixel] = t;
}

EventStatsAccumulator::EventStatsAccumulator(int width, int height, const SequenceStatsOptions& options)
    : impl_(std::make_shared<Impl>()) {
  options.validate();
  if (width <= 0 || height <= 0) throw Error("event statistics need the sensor size (width_px, height_px)");
  Impl& m = *impl_;
  m.width = width;
  m.height = height;
  m.window_ns = secondsToNs(options.rate_window_s);
  m.burst_gap_ns = secondsToNs(options.burst_gap_s);
  m.isolation_ns = secondsToNs(options.isolation_window_s);
  const auto pixels = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  m.last_same.assign(2 * pixels, kNever);
  m.burst_events.assign(2 * pixels, 0);
  m.last_any.assign(pixels, kNever);
  m.candidate.assign(pixels, 0);
  m.pixel_events.assign(pixels, 0);
  m.intervals.countBelow(kNsPerMs);
}

void EventStatsAccumulator::add(const EventArray& events) {
  for (std::size_t i = 0; i < events.size(); ++i)
    impl_->addOne(events.t()[i], events.x()[i], events.y()[i], events.p()[i] != 0);
}

EventStreamStats EventStatsAccumulator::finish() {
  Impl& m = *impl_;
  EventStreamStats s = m.s;
  s.present = true;
  for (std::size_t i = 0; i < m.burst_events.size(); ++i)
    if (m.burst_events[i] > 0) m.bursts.add(m.burst_events[i]);
  for (const std::uint8_t c : m.candidate) s.isolated_count += c;
  const auto whole = static_cast<std::size_t>((s.t_last_ns - s.t_first_ns) / m.window_ns);
  s.window_counts.resize(s.count == 0 ? 0 : whole);
  std::vector<double> rates;
  rates.reserve(s.window_counts.size());
  for (const auto c : s.window_counts) rates.push_back(static_cast<double>(c) / nsToSeconds(m.window_ns));
  s.window_rate_hz = quantilesOf(std::move(rates));
  s.interval_count = m.intervals.count();
  s.interval_s = m.intervals.quantilesS();
  s.interval_under_1ms_fraction =
      s.interval_count ? static_cast<double>(m.intervals.below()) / static_cast<double>(s.interval_count) : 0.0;
  s.burst_count = m.bursts.count();
  s.events_per_burst = m.bursts.quantiles();
  const double pixels = static_cast<double>(m.width) * m.height;
  s.isolated_rate_hz_per_pixel = s.durationS() > 0 ? static_cast<double>(s.isolated_count) / (pixels * s.durationS()) : 0.0;
  std::vector<double> counts(m.pixel_events.begin(), m.pixel_events.end());
  s.pixel_count = quantilesOf(std::move(counts));
  return s;
}

double EventStreamStats::meanRateHz() const {
  return durationS() > 0 ? static_cast<double>(count) / durationS() : 0.0;
}
double EventStreamStats::onFraction() const {
  return count ? static_cast<double>(on_count) / static_cast<double>(count) : 0.0;
}

}  // namespace evio::experiments

#include "evio/estimator/pipeline/tracks_input.h"

#include <algorithm>
#include <unordered_map>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"

namespace evio::estimator {

namespace {

SynchronizerOptions syncOptions(const TracksInputOptions& o) {
  SynchronizerOptions s;
  if (o.rate_hz > 0.0) {
    s.trigger = "fixed_rate";
    s.rate_hz = o.rate_hz;
  } else {
    s.trigger = "track_time";
  }
  return s;
}

}  // namespace

TracksInput::TracksInput(const std::string& path, const TracksInputOptions& options, std::uint64_t seed)
    : TracksInput(io::readTracksText(path), options, seed) {}

TracksInput::TracksInput(std::vector<io::TrackSample> samples, const TracksInputOptions& options, std::uint64_t seed)
    : options_(options), samples_(std::move(samples)), sync_(syncOptions(options)) {
  options_.validate();
  prepare(seed);
}

void TracksInput::prepare(std::uint64_t seed) {
  std::stable_sort(samples_.begin(), samples_.end(), [](const io::TrackSample& a, const io::TrackSample& b) {
    return a.t_ns != b.t_ns ? a.t_ns < b.t_ns : a.id < b.id;
  });
  if (options_.noise_px > 0.0) {
    RandomStream rng(seed, "track_noise");
    for (auto& s : samples_) {
      s.uv.x() += options_.noise_px * rng.normal();
      s.uv.y() += options_.noise_px * rng.normal();
    }
  }
  // Split tracks at gaps longer than max_gap_s: later segments get new ids
  // above every id of the file, in order of their first sample.
  std::int64_t next_id = 0;
  for (const auto& s : samples_) next_id = std::max(next_id, s.id + 1);
  const TimeNs max_gap = secondsToNs(options_.max_gap_s);
  struct Segment {
    std::int64_t id;  // current id of the segment
    TimeNs last;
  };
  std::unordered_map<std::int64_t, Segment> open;  // file id → its current segment
  for (auto& s : samples_) {
    auto [it, inserted] = open.try_emplace(s.id, Segment{s.id, s.t_ns});
    if (!inserted) {
      if (s.t_ns - it->second.last > max_gap) {
        last_t_.emplace_back(it->second.id, it->second.last);
        it->second.id = next_id++;
        ++splits_;
      }
      it->second.last = s.t_ns;
    }
    s.id = it->second.id;
  }
  for (const auto& [file_id, seg] : open) last_t_.emplace_back(seg.id, seg.last);
  std::sort(last_t_.begin(), last_t_.end());
}

void TracksInput::advanceTo(TimeNs t_ns, std::vector<MeasurementSet>& out) {
  TrackPoints points;
  while (next_ < samples_.size() && samples_[next_].t_ns <= t_ns) {
    const TimeNs t = samples_[next_].t_ns;
    // Tracks whose last sample came before t end now.
    points.clear();
    for (FeatureId id : ending_) {
      TrackPoint p;
      p.feature_id = id;
      p.t_ns = t;
      p.status = TrackStatus::kLost;
      points.push_back(p);
    }
    ending_.clear();
    if (!points.empty()) sync_.addTrackPoints(points);
    if (next_ > 0) sync_.advanceTime(t - 1);  // fixed-rate updates strictly before t (the grid starts at the first t)
    points.clear();
    for (; next_ < samples_.size() && samples_[next_].t_ns == t; ++next_) {
      const io::TrackSample& s = samples_[next_];
      TrackPoint p;
      p.feature_id = s.id;
      p.t_ns = s.t_ns;
      p.uv = s.uv;
      p.status = TrackStatus::kTracked;
      points.push_back(p);
      const auto it = std::lower_bound(last_t_.begin(), last_t_.end(), s.id,
                                       [](const auto& e, std::int64_t id) { return e.first < id; });
      if (it != last_t_.end() && it->first == s.id && it->second == s.t_ns) ending_.push_back(s.id);
    }
    sync_.addTrackPoints(points);
    sync_.advanceTime(t);
  }
  MeasurementSet set;
  while (sync_.poll(&set)) out.push_back(std::move(set));
}

}  // namespace evio::estimator

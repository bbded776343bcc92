#include "evio/experiments/track_metrics.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "evio/core/error.h"
#include "evio/core/io/text_scanner.h"

namespace evio::experiments {

namespace {

using Track = std::vector<io::TrackSample>;

std::map<std::int64_t, Track> byId(const std::vector<io::TrackSample>& samples) {
  std::map<std::int64_t, Track> tracks;
  for (const auto& s : samples) tracks[s.id].push_back(s);
  for (auto& [id, t] : tracks)
    std::stable_sort(t.begin(), t.end(), [](const auto& a, const auto& b) { return a.t_ns < b.t_ns; });
  return tracks;
}

/// Ground truth at t_ns, linearly interpolated; nullopt outside the track or
/// across a gap longer than max_gap_ns.
std::optional<Vec2> at(const Track& track, TimeNs t_ns, TimeNs max_gap_ns) {
  if (track.empty() || t_ns < track.front().t_ns || t_ns > track.back().t_ns) return std::nullopt;
  const auto it = std::lower_bound(track.begin(), track.end(), t_ns,
                                   [](const io::TrackSample& s, TimeNs t) { return s.t_ns < t; });
  if (it->t_ns == t_ns) return it->uv;
  const auto& b = *it;
  const auto& a = *(it - 1);
  if (b.t_ns - a.t_ns > max_gap_ns) return std::nullopt;
  const double w = static_cast<double>(t_ns - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return (1.0 - w) * a.uv + w * b.uv;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  double m = v[k];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k)));
  return m;
}

}  // namespace

void TrackMetricsOptions::validate() const {
  requireField(match == "nearest" || match == "id", "match", "must be nearest or id (got '" + match + "')");
  requirePositive("association_radius_px", association_radius_px);
  requirePositive("max_error_px", max_error_px);
  requirePositive("max_gap_s", max_gap_s);
  requirePositive("age_bin_s", age_bin_s);
  requirePositive("alive_bin_s", alive_bin_s);
}

namespace {

/// Accumulates the scores of tracks whose truth is known for their first
/// samples (truth_uv[k] for sample k < truth_uv.size()).
class Scorer {
 public:
  explicit Scorer(const TrackMetricsOptions& options) : options_(options) {}

  void add(const Track& track, const std::vector<Vec2>& truth_uv) {
    ++m_.matched_tracks;
    const TimeNs t0 = track.front().t_ns;
    double age = 0.0;
    std::size_t k = 0;
    bool error_ended = false;
    for (; k < truth_uv.size(); ++k) {
      const double err = (track[k].uv - truth_uv[k]).norm();
      if (err > options_.max_error_px) {
        error_ended = true;
        break;
      }
      age = nsToSeconds(track[k].t_ns - t0);
      errors_.push_back(err);
      const auto bin = static_cast<std::size_t>(std::floor(age / options_.age_bin_s));
      if (bin >= bin_sum_.size()) {
        bin_sum_.resize(bin + 1, 0.0);
        bin_count_.resize(bin + 1, 0);
      }
      bin_sum_[bin] += err;
      ++bin_count_[bin];
    }
    if (error_ended)
      ++m_.ended_by_error;
    else if (k < track.size())
      ++m_.ended_by_truth;
    else
      ++m_.ended_by_track;
    ages_.push_back(age);
  }

  TrackMetrics finish(TrackMetrics m) const {
    m.matched_tracks = m_.matched_tracks;
    m.ended_by_error = m_.ended_by_error;
    m.ended_by_truth = m_.ended_by_truth;
    m.ended_by_track = m_.ended_by_track;
    m.scored_samples = errors_.size();
    if (!errors_.empty()) {
      double sum = 0.0;
      for (double e : errors_) sum += e;
      m.mean_error_px = sum / static_cast<double>(errors_.size());
      m.median_error_px = median(errors_);
    }
    if (!ages_.empty()) {
      double sum = 0.0;
      for (double a : ages_) sum += a;
      m.mean_feature_age_s = sum / static_cast<double>(ages_.size());
      m.median_feature_age_s = median(ages_);
    }
    for (std::size_t b = 0; b < bin_sum_.size(); ++b)
      if (bin_count_[b] > 0)
        m.error_vs_age.push_back(AgeBin{static_cast<double>(b) * options_.age_bin_s,
                                        bin_sum_[b] / static_cast<double>(bin_count_[b]), bin_count_[b]});
    return m;
  }

 private:
  const TrackMetricsOptions& options_;
  TrackMetrics m_;
  std::vector<double> errors_, ages_, bin_sum_;
  std::vector<std::uint64_t> bin_count_;
};

double meanLength(const std::map<std::int64_t, Track>& est) {
  double sum = 0.0;
  for (const auto& [id, t] : est) sum += nsToSeconds(t.back().t_ns - t.front().t_ns);
  return est.empty() ? 0.0 : sum / static_cast<double>(est.size());
}

/// Alive counts on a regular grid over [t0, t1]; truth_alive(t) counts the
/// visible ground truth.
template <class TruthAlive>
std::vector<AliveSample> aliveCounts(const std::map<std::int64_t, Track>& est, TimeNs t0, TimeNs t1, double bin_s,
                                     const TruthAlive& truth_alive) {
  std::vector<AliveSample> out;
  const TimeNs step = secondsToNs(bin_s);
  for (TimeNs t = t0; t <= t1; t += step) {
    AliveSample a;
    a.t_s = nsToSeconds(t);
    for (const auto& [id, tr] : est) a.estimated += (tr.front().t_ns <= t && t <= tr.back().t_ns) ? 1 : 0;
    a.truth = truth_alive(t);
    out.push_back(a);
  }
  return out;
}

}  // namespace

TrackMetrics evaluateTracks(const std::vector<io::TrackSample>& estimated, const std::vector<io::TrackSample>& truth,
                            const TrackMetricsOptions& options) {
  options.validate();
  const auto est = byId(estimated);
  const auto gt = byId(truth);
  const TimeNs max_gap_ns = secondsToNs(options.max_gap_s);
  TrackMetrics m;
  m.mode = "tracks-" + options.match;
  m.estimated_tracks = est.size();
  m.mean_track_length_s = meanLength(est);
  Scorer scorer(options);
  for (const auto& [id, track] : est) {
    const io::TrackSample& first = track.front();
    const Track* match = nullptr;
    if (options.match == "id") {
      const auto it = gt.find(id);
      if (it != gt.end() && at(it->second, first.t_ns, max_gap_ns)) match = &it->second;
    } else {
      double best = options.association_radius_px;
      for (const auto& [gid, g] : gt) {
        const auto p = at(g, first.t_ns, max_gap_ns);
        if (!p) continue;
        const double d = (*p - first.uv).norm();
        if (d <= best) {
          best = d;
          match = &g;
        }
      }
    }
    if (match == nullptr) {
      ++m.unevaluable_tracks;
      continue;
    }
    // "nearest": the estimated start is taken as exact and the ground-truth
    // track's displacement since then as the true motion.
    const Vec2 offset = options.match == "nearest" ? Vec2(first.uv - *at(*match, first.t_ns, max_gap_ns)) : Vec2::Zero();
    std::vector<Vec2> uv;
    for (const auto& s : track) {
      const auto p = at(*match, s.t_ns, max_gap_ns);
      if (!p) break;  // ground truth ends (occluded or out of view)
      uv.push_back(*p + offset);
    }
    scorer.add(track, uv);
  }
  m = scorer.finish(m);

  // Alive counts on a regular grid over the span of both inputs.
  TimeNs t0 = 0, t1 = -1;
  bool any = false;
  for (const auto* set : {&est, &gt})
    for (const auto& [id, t] : *set) {
      t0 = any ? std::min(t0, t.front().t_ns) : t.front().t_ns;
      t1 = any ? std::max(t1, t.back().t_ns) : t.back().t_ns;
      any = true;
    }
  if (any)
    m.alive = aliveCounts(est, t0, t1, options.alive_bin_s, [&](TimeNs t) {
      std::uint64_t n = 0;
      for (const auto& [id, tr] : gt) n += at(tr, t, max_gap_ns) ? 1 : 0;
      return n;
    });
  return m;
}

TrackMetrics evaluateTracks(const std::vector<io::TrackSample>& estimated, const DepthTrackTruth& truth,
                            const TrackMetricsOptions& options) {
  options.validate();
  const auto est = byId(estimated);
  TrackMetrics m;
  m.mode = "depth";
  m.estimated_tracks = est.size();
  m.mean_track_length_s = meanLength(est);
  Scorer scorer(options);
  std::vector<std::pair<TimeNs, TimeNs>> truth_spans;  // first sample .. last sample with truth
  for (const auto& [id, track] : est) {
    const TrackTruth tt = truth.truthOf(track);
    switch (tt.status) {
      case TrackTruthStatus::kOk:
        break;
      case TrackTruthStatus::kNoDepthFrame:
        ++m.unevaluable_no_depth_frame;
        break;
      case TrackTruthStatus::kNoSurface:
      case TrackTruthStatus::kDiscontinuity:
        ++m.unevaluable_depth;
        break;
    }
    if (tt.status != TrackTruthStatus::kOk) {
      ++m.unevaluable_tracks;
      continue;
    }
    if (!tt.uv.empty()) truth_spans.emplace_back(track.front().t_ns, track[tt.uv.size() - 1].t_ns);
    scorer.add(track, tt.uv);
  }
  m = scorer.finish(m);
  if (!est.empty()) {
    TimeNs t0 = est.begin()->second.front().t_ns, t1 = est.begin()->second.back().t_ns;
    for (const auto& [id, t] : est) {
      t0 = std::min(t0, t.front().t_ns);
      t1 = std::max(t1, t.back().t_ns);
    }
    m.alive = aliveCounts(est, t0, t1, options.alive_bin_s, [&](TimeNs t) {
      std::uint64_t n = 0;
      for (const auto& [a, b] : truth_spans) n += (a <= t && t <= b) ? 1 : 0;
      return n;
    });
  }
  return m;
}

std::string trackMetricsJson(const TrackMetrics& m) {
  std::string s = "{\n";
  const auto num = [&](const char* key, double v, bool comma = true) {
    s += std::string("  \"") + key + "\": ";
    io::appendDouble(s, v);
    s += comma ? ",\n" : "\n";
  };
  s += "  \"mode\": \"" + m.mode + "\",\n";
  num("estimated_tracks", static_cast<double>(m.estimated_tracks));
  num("matched_tracks", static_cast<double>(m.matched_tracks));
  num("unevaluable_tracks", static_cast<double>(m.unevaluable_tracks));
  num("unevaluable_no_depth_frame", static_cast<double>(m.unevaluable_no_depth_frame));
  num("unevaluable_depth", static_cast<double>(m.unevaluable_depth));
  num("ended_by_error", static_cast<double>(m.ended_by_error));
  num("ended_by_truth", static_cast<double>(m.ended_by_truth));
  num("ended_by_track", static_cast<double>(m.ended_by_track));
  num("scored_samples", static_cast<double>(m.scored_samples));
  num("mean_error_px", m.mean_error_px);
  num("median_error_px", m.median_error_px);
  num("mean_feature_age_s", m.mean_feature_age_s);
  num("median_feature_age_s", m.median_feature_age_s);
  num("mean_track_length_s", m.mean_track_length_s);
  s += "  \"error_vs_age\": [";
  for (std::size_t i = 0; i < m.error_vs_age.size(); ++i) {
    const auto& b = m.error_vs_age[i];
    s += i == 0 ? "\n    {" : ",\n    {";
    s += "\"age_s\": ";
    io::appendDouble(s, b.age_s);
    s += ", \"mean_error_px\": ";
    io::appendDouble(s, b.mean_error_px);
    s += ", \"samples\": ";
    io::appendInt(s, static_cast<std::int64_t>(b.samples));
    s += "}";
  }
  s += "\n  ],\n  \"alive\": [";
  for (std::size_t i = 0; i < m.alive.size(); ++i) {
    const auto& a = m.alive[i];
    s += i == 0 ? "\n    {" : ",\n    {";
    s += "\"t_s\": ";
    io::appendDouble(s, a.t_s);
    s += ", \"estimated\": ";
    io::appendInt(s, static_cast<std::int64_t>(a.estimated));
    s += ", \"truth\": ";
    io::appendInt(s, static_cast<std::int64_t>(a.truth));
    s += "}";
  }
  s += "\n  ]\n}\n";
  return s;
}

std::string errorVsAgeCsv(const TrackMetrics& m) {
  std::string s = "age_s,mean_error_px,samples\n";
  for (const auto& b : m.error_vs_age) {
    io::appendDouble(s, b.age_s);
    s += ",";
    io::appendDouble(s, b.mean_error_px);
    s += ",";
    io::appendInt(s, static_cast<std::int64_t>(b.samples));
    s += "\n";
  }
  return s;
}

std::string aliveCsv(const TrackMetrics& m) {
  std::string s = "t_s,estimated,truth\n";
  for (const auto& a : m.alive) {
    io::appendDouble(s, a.t_s);
    s += ",";
    io::appendInt(s, static_cast<std::int64_t>(a.estimated));
    s += ",";
    io::appendInt(s, static_cast<std::int64_t>(a.truth));
    s += "\n";
  }
  return s;
}

}  // namespace evio::experiments

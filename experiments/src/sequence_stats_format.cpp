// The JSON document and the plain table of `evio stats` (sequence_stats.h).
#include <cstdio>

#include "evio/experiments/sequence_stats.h"

namespace evio::experiments {

namespace {

JsonValue quantilesJson(const Quantiles& q, std::initializer_list<const char*> keys) {
  JsonValue o = JsonValue::object();
  for (const std::string key : keys) {
    const double v = key == "p1" ? q.p1 : key == "p5" ? q.p5 : key == "p50" ? q.p50 : key == "p90" ? q.p90
                   : key == "p99" ? q.p99 : key == "min" ? q.min : q.max;
    o.set(key, JsonValue::number(v));
  }
  return o;
}

JsonValue eventsJson(const EventStreamStats& e, const SequenceStatsOptions& o) {
  JsonValue j = JsonValue::object();
  j.set("file", JsonValue::string(e.file));
  j.set("count", JsonValue::integer(static_cast<std::int64_t>(e.count)));
  j.set("duration_s", JsonValue::number(e.durationS()));
  j.set("mean_rate_hz", JsonValue::number(e.meanRateHz()));
  j.set("on_fraction", JsonValue::number(e.onFraction()));
  j.set("rate_window_s", JsonValue::number(o.rate_window_s));
  j.set("rate_hz", quantilesJson(e.window_rate_hz, {"p50", "p90", "max"}));
  JsonValue series = JsonValue::array();
  for (const auto c : e.window_counts) series.push(JsonValue::number(static_cast<double>(c) / o.rate_window_s));
  j.set("rate_series_hz", std::move(series));
  j.set("interval_count", JsonValue::integer(static_cast<std::int64_t>(e.interval_count)));
  j.set("interval_s", quantilesJson(e.interval_s, {"min", "p1", "p5", "p50"}));
  j.set("interval_under_1ms_fraction", JsonValue::number(e.interval_under_1ms_fraction));
  j.set("burst_gap_s", JsonValue::number(o.burst_gap_s));
  j.set("burst_count", JsonValue::integer(static_cast<std::int64_t>(e.burst_count)));
  j.set("events_per_burst", quantilesJson(e.events_per_burst, {"p50", "p90", "max"}));
  j.set("isolation_window_s", JsonValue::number(o.isolation_window_s));
  j.set("isolated_count", JsonValue::integer(static_cast<std::int64_t>(e.isolated_count)));
  j.set("isolated_rate_hz_per_pixel", JsonValue::number(e.isolated_rate_hz_per_pixel));
  j.set("pixel_count", quantilesJson(e.pixel_count, {"p50", "p90", "p99", "max"}));
  return j;
}

JsonValue framesJson(const FrameStreamStats& f) {
  JsonValue j = JsonValue::object();
  j.set("count", JsonValue::integer(static_cast<std::int64_t>(f.count)));
  j.set("width", JsonValue::integer(f.width));
  j.set("height", JsonValue::integer(f.height));
  j.set("rate_hz", JsonValue::number(f.rateHz()));
  j.set("exposure_s", f.exposure_s ? JsonValue::number(*f.exposure_s) : JsonValue::null());
  j.set("exposure_note", JsonValue::string(f.exposure_note));
  j.set("brightness_mean_dn", JsonValue::number(f.brightness_mean_dn));
  j.set("fraction_at_0", JsonValue::number(f.fraction_at_0));
  j.set("fraction_at_255", JsonValue::number(f.fraction_at_255));
  j.set("max_dn", quantilesJson(f.max_dn, {"min", "p50", "max"}));
  j.set("fraction_at_max", JsonValue::number(f.fraction_at_max));
  j.set("white_level_dn", quantilesJson(f.white_level_dn, {"min", "p50", "max"}));
  j.set("fraction_near_white", JsonValue::number(f.fraction_near_white));
  j.set("laplacian_variance_dn2", JsonValue::number(f.laplacian_variance_dn2));
  JsonValue h = JsonValue::array();
  for (const auto c : f.histogram) h.push(JsonValue::integer(static_cast<std::int64_t>(c)));
  j.set("histogram", std::move(h));
  return j;
}

/// `v` with `decimals` digits after the point, or `digits` significant ones.
std::string fix(int decimals, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}
std::string gen(int digits, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  return buf;
}

std::string row(const std::string& name, const std::string& value) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%-38s %s\n", name.c_str(), value.c_str());
  return buf;
}

}  // namespace

JsonValue sequenceStatsJson(const SequenceStats& s) {
  JsonValue j = JsonValue::object();
  j.set("folder", JsonValue::string(s.folder));
  j.set("width", JsonValue::integer(s.width));
  j.set("height", JsonValue::integer(s.height));
  j.set("resolution_source", JsonValue::string(s.resolution_source));
  j.set("events", s.events.present ? eventsJson(s.events, s.options) : JsonValue::null());
  j.set("frames", s.frames.present ? framesJson(s.frames) : JsonValue::null());
  return j;
}

std::string formatSequenceStats(const SequenceStats& s) {
  std::string out = row("sequence", s.folder);
  out += row("sensor", std::to_string(s.width) + "x" + std::to_string(s.height) + " (from " + s.resolution_source + ")");
  const EventStreamStats& e = s.events;
  if (!e.present) out += row("events", "none");
  else {
    const auto ms = [](double v) { return fix(3, v * 1e3); };
    const auto& o = s.options;
    out += row("events", std::to_string(e.count) + " in " + fix(3, e.durationS()) + " s, mean " +
                             gen(4, e.meanRateHz()) + " ev/s, ON fraction " + fix(3, e.onFraction()));
    out += row("rate (" + gen(6, o.rate_window_s * 1e3) + " ms windows) p50/p90/max",
               gen(4, e.window_rate_hz.p50) + " / " + gen(4, e.window_rate_hz.p90) + " / " +
                   gen(4, e.window_rate_hz.max) + " ev/s");
    out += row("same-pixel interval min/p1/p5/p50",
               ms(e.interval_s.min) + " / " + ms(e.interval_s.p1) + " / " + ms(e.interval_s.p5) + " / " +
                   ms(e.interval_s.p50) + " ms");
    out += row("intervals under 1 ms", fix(4, e.interval_under_1ms_fraction) + " of " + std::to_string(e.interval_count));
    out += row("events per burst (gap " + gen(6, o.burst_gap_s * 1e3) + " ms) p50/p90",
               gen(6, e.events_per_burst.p50) + " / " + gen(6, e.events_per_burst.p90) + " (" +
                   std::to_string(e.burst_count) + " bursts)");
    out += row("isolated (3x3, +-" + gen(6, o.isolation_window_s * 1e3) + " ms)",
               gen(4, e.isolated_rate_hz_per_pixel) + " Hz/px (" + std::to_string(e.isolated_count) + " events)");
    out += row("events per pixel p50/p90/p99/max", gen(6, e.pixel_count.p50) + " / " + gen(6, e.pixel_count.p90) +
                                                      " / " + gen(6, e.pixel_count.p99) + " / " + gen(6, e.pixel_count.max));
  }
  const FrameStreamStats& f = s.frames;
  if (!f.present) return out + row("frames", "none");
  out += row("frames", std::to_string(f.count) + " (" + std::to_string(f.width) + "x" + std::to_string(f.height) + "), " +
                           fix(2, f.rateHz()) + " Hz");
  out += row("exposure", f.exposure_s ? fix(6, *f.exposure_s) + " s" : "unknown: " + f.exposure_note);
  out += row("brightness mean", fix(2, f.brightness_mean_dn) + " DN");
  out += row("pixels at 0 / at 255", fix(4, f.fraction_at_0) + " / " + fix(4, f.fraction_at_255));
  out += row("frame max DN p50; pixels at it", gen(6, f.max_dn.p50) + " DN; " + fix(4, f.fraction_at_max));
  out += row("white level p50; pixels within 10 DN", gen(6, f.white_level_dn.p50) + " DN; " + fix(4, f.fraction_near_white));
  out += row("sharpness (Laplacian variance)", fix(1, f.laplacian_variance_dn2) + " DN^2");
  return out;
}

}  // namespace evio::experiments

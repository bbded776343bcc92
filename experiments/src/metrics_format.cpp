#include "evio/experiments/metrics_format.h"

#include <cmath>
#include <cstdarg>
#include <cstdio>

#include "evio/core/io/text_scanner.h"

namespace evio::experiments {

namespace {

JsonValue pathOrNull(const std::string& path) { return path.empty() ? JsonValue::null() : JsonValue::string(path); }

JsonValue stats(const ErrorStats& s) {
  JsonValue o = JsonValue::object();
  o.set("count", JsonValue::integer(static_cast<std::int64_t>(s.count)));
  o.set("rmse", JsonValue::number(s.rmse));
  o.set("mean", JsonValue::number(s.mean));
  o.set("median", JsonValue::number(s.median));
  o.set("max", JsonValue::number(s.max));
  return o;
}

/// printf-style formatting of one line appended to `out`.
__attribute__((format(printf, 2, 3))) void appendLine(std::string& out, const char* fmt, ...) {
  char buf[512];
  va_list args;
  va_start(args, fmt);
  std::vsnprintf(buf, sizeof(buf), fmt, args);
  va_end(args);
  out += buf;
  out += "\n";
}

void appendNumber(std::string& out, double v) {
  if (std::isfinite(v)) io::appendDouble(out, v == 0.0 ? 0.0 : v);
}

}  // namespace

JsonValue metricsJson(const Metrics& m, const EvaluationOptions& options, const MetricsSources& sources) {
  const std::string tag = m.alignment.describe();
  JsonValue j = JsonValue::object();
  j.set("format", JsonValue::string("evio-metrics/1"));
  JsonValue& in = j.set("inputs", JsonValue::object());
  in.set("estimate", pathOrNull(sources.estimate));
  in.set("groundtruth", pathOrNull(sources.groundtruth));
  in.set("covariance", pathOrNull(sources.covariance));
  in.set("timing", pathOrNull(sources.timing));
  in.set("status", pathOrNull(sources.status));
  j.set("status", JsonValue::string(m.status));
  j.set("cause", JsonValue::string(m.cause));
  j.set("estimator_status", JsonValue::string(m.estimator_status));

  JsonValue& as = j.set("association", JsonValue::object());
  as.set("estimate_poses", JsonValue::integer(static_cast<std::int64_t>(m.estimate_poses)));
  as.set("groundtruth_poses", JsonValue::integer(static_cast<std::int64_t>(m.groundtruth_poses)));
  as.set("matched_poses", JsonValue::integer(static_cast<std::int64_t>(m.matched_poses)));
  as.set("matched_share", JsonValue::number(m.matched_share));
  as.set("max_time_difference_s", JsonValue::number(options.association.max_time_difference_s));
  as.set("time_offset_s", JsonValue::number(options.association.time_offset_s));

  JsonValue& gt = j.set("groundtruth", JsonValue::object());
  gt.set("duration_s", JsonValue::number(m.groundtruth_duration_s));
  gt.set("length_m", JsonValue::number(m.groundtruth_length_m));

  const Alignment& a = m.alignment;
  JsonValue& al = j.set("alignment", JsonValue::object());
  al.set("describe", JsonValue::string(tag));
  al.set("type", JsonValue::string(alignmentTypeName(a.type)));
  al.set("window", JsonValue::string(a.options.window));
  al.set("first_n", JsonValue::integer(a.options.first_n));
  al.set("start_s", JsonValue::number(a.options.start_s));
  al.set("end_s", JsonValue::number(a.options.end_s));
  al.set("poses_used", JsonValue::integer(static_cast<std::int64_t>(a.poses_used)));
  al.set("window_start_s", JsonValue::number(a.window_start_s));
  al.set("window_end_s", JsonValue::number(a.window_end_s));
  al.set("rotation_from_orientation", JsonValue::boolean(a.rotation_from_orientation));
  al.set("scale", JsonValue::number(a.transform.scale));
  JsonValue& R = al.set("rotation", JsonValue::array());
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R.push(JsonValue::number(a.transform.R(r, c)));
  JsonValue& t = al.set("translation", JsonValue::array());
  for (int r = 0; r < 3; ++r) t.push(JsonValue::number(a.transform.t(r)));

  JsonValue& p = j.set("paper", JsonValue::object());
  p.set("alignment", JsonValue::string(tag));
  p.set("mpe_percent", JsonValue::number(m.paper.mpe_percent));
  p.set("mre_deg_per_m", JsonValue::number(m.paper.mre_deg_per_m));
  p.set("mye_deg_per_m", JsonValue::number(m.paper.mye_deg_per_m));
  p.set("mean_position_m", JsonValue::number(m.paper.mean_position_m));
  p.set("mean_rotation_deg", JsonValue::number(m.paper.mean_rotation_deg));
  p.set("mean_yaw_deg", JsonValue::number(m.paper.mean_yaw_deg));

  JsonValue& ate = j.set("ate", JsonValue::object());
  ate.set("alignment", JsonValue::string(tag));
  ate.set("position_m", stats(m.ate.position_m));
  ate.set("rotation_deg", stats(m.ate.rotation_deg));

  JsonValue& d = j.set("drift", JsonValue::object());
  d.set("alignment", JsonValue::string(tag));
  d.set("final_position_m", JsonValue::number(m.drift.final_position_m));
  d.set("final_rotation_deg", JsonValue::number(m.drift.final_rotation_deg));
  d.set("position_m_per_min", JsonValue::number(m.drift.position_m_per_min));
  d.set("rotation_deg_per_min", JsonValue::number(m.drift.rotation_deg_per_min));

  JsonValue& rpe = j.set("rpe", JsonValue::object());
  rpe.set("alignment", JsonValue::string(tag));
  for (const auto& r : m.rpe) {
    JsonValue& l = rpe.set(r.label, JsonValue::object());
    l.set("length_m", JsonValue::number(r.length_m));
    l.set("translation_percent", stats(r.translation_percent));
    l.set("yaw_deg", stats(r.yaw_deg));
    l.set("yaw_deg_per_m", JsonValue::number(r.yaw_deg_per_m));
    l.set("gravity_deg", stats(r.gravity_deg));
  }

  JsonValue& n = j.set("nees", JsonValue::object());
  n.set("available", JsonValue::boolean(m.nees.available));
  if (m.nees.available) {
    n.set("alignment", JsonValue::string(options.nees.use_alignment ? tag : "none (nees.use_alignment false)"));
    n.set("rotation_error", JsonValue::string(options.nees.rotation_error));
    n.set("poses", JsonValue::integer(static_cast<std::int64_t>(m.nees.poses)));
    n.set("singular", JsonValue::integer(static_cast<std::int64_t>(m.nees.singular)));
    n.set("mean_pose", JsonValue::number(m.nees.mean_pose));
    n.set("mean_position", JsonValue::number(m.nees.mean_position));
    n.set("mean_orientation", JsonValue::number(m.nees.mean_orientation));
    n.set("share_in_bounds", JsonValue::number(m.nees.share_in_bounds));
    const auto [lo, hi] = neesBounds(6, 1);
    JsonValue& b = n.set("bounds_pose_95", JsonValue::array());
    b.push(JsonValue::number(lo));
    b.push(JsonValue::number(hi));
  }

  JsonValue& rtf = j.set("rtf", JsonValue::object());
  rtf.set("available", JsonValue::boolean(m.rtf.available));
  if (m.rtf.available) {
    rtf.set("grid_s", JsonValue::number(m.rtf.grid_s));
    rtf.set("intervals", JsonValue::integer(static_cast<std::int64_t>(m.rtf.samples.size())));
    rtf.set("median", JsonValue::number(m.rtf.median));
    rtf.set("max", JsonValue::number(m.rtf.max));
    rtf.set("overall", JsonValue::number(m.rtf.overall));
    rtf.set("mean_event_rate_hz", JsonValue::number(m.rtf.mean_event_rate_hz));
    if (m.rtf.features_known) {
      rtf.set("median_features", JsonValue::number(m.rtf.median_features));
      rtf.set("median_per_feature", JsonValue::number(m.rtf.median_per_feature));
    }
  }

  JsonValue& dv = j.set("divergence", JsonValue::object());
  dv.set("alignment",
         JsonValue::string(options.divergence.use_alignment ? tag : "none (divergence.use_alignment false)"));
  dv.set("diverged", JsonValue::boolean(m.divergence.diverged));
  dv.set("time_s", m.divergence.diverged ? JsonValue::number(m.divergence.time_s) : JsonValue::null());
  dv.set("cause", JsonValue::string(m.divergence.cause));
  dv.set("max_ratio", JsonValue::number(m.divergence.max_ratio));
  dv.set("truth_diverged", JsonValue::boolean(m.truth_divergence.diverged));
  dv.set("truth_time_s",
         m.truth_divergence.diverged ? JsonValue::number(m.truth_divergence.time_s) : JsonValue::null());
  dv.set("fraction_of_distance", JsonValue::number(options.divergence.fraction_of_distance));
  dv.set("offset_m", JsonValue::number(options.divergence.offset_m));

  JsonValue& c = j.set("completion", JsonValue::object());
  c.set("alignment", JsonValue::string(tag));
  c.set("share", JsonValue::number(m.completion));
  c.set("max_gap_s", JsonValue::number(options.completion_max_gap_s));
  return j;
}

std::string csvField(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos) return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string metricsCsv(const JsonValue& metrics_json) {
  std::vector<std::pair<std::string, std::string>> flat;
  metrics_json.flatten(flat);
  std::string header, row;
  bool first = true;
  for (const auto& [k, v] : flat) {
    if (k.rfind("inputs.", 0) == 0) continue;
    if (!first) {
      header += ",";
      row += ",";
    }
    first = false;
    header += csvField(k);
    row += csvField(v);
  }
  return header + "\n" + row + "\n";
}

std::string metricsTable(const Metrics& m) {
  std::string s;
  s += "status            " + m.status + (m.cause.empty() ? "" : " (" + m.cause + ")") + "\n";
  appendLine(s, "association       %zu of %zu estimate poses matched (%.1f %%); ground truth %.3f s, %.3f m", m.matched_poses,
       m.estimate_poses, 100.0 * m.matched_share, m.groundtruth_duration_s, m.groundtruth_length_m);
  appendLine(s, "alignment         %s", m.alignment.describe().c_str());
  appendLine(s, "completion        %.1f %%", 100.0 * m.completion);
  s += "\n";
  appendLine(s, "%-22s %12s %12s %12s %12s", "metric", "rmse", "mean", "median", "max");
  appendLine(s, "%-22s %12.4g %12.4g %12.4g %12.4g", "ATE position [m]", m.ate.position_m.rmse, m.ate.position_m.mean,
       m.ate.position_m.median, m.ate.position_m.max);
  appendLine(s, "%-22s %12.4g %12.4g %12.4g %12.4g", "ATE rotation [deg]", m.ate.rotation_deg.rmse, m.ate.rotation_deg.mean,
       m.ate.rotation_deg.median, m.ate.rotation_deg.max);
  for (const auto& r : m.rpe) {
    if (r.translation_percent.count == 0) continue;
    std::string name = "RPE " + r.label + " [%]";
    appendLine(s, "%-22s %12.4g %12.4g %12.4g %12.4g", name.c_str(), r.translation_percent.rmse, r.translation_percent.mean,
         r.translation_percent.median, r.translation_percent.max);
    name = "RPE " + r.label + " yaw [deg]";
    appendLine(s, "%-22s %12.4g %12.4g %12.4g %12.4g", name.c_str(), r.yaw_deg.rmse, r.yaw_deg.mean, r.yaw_deg.median,
         r.yaw_deg.max);
  }
  s += "\n";
  appendLine(s, "MPE %.4g %%   MRE %.4g deg/m   MYE %.4g deg/m   (L_gt %.3f m)", m.paper.mpe_percent, m.paper.mre_deg_per_m,
       m.paper.mye_deg_per_m, m.groundtruth_length_m);
  appendLine(s, "mean errors       %.4g m, %.4g deg, yaw %.4g deg", m.paper.mean_position_m, m.paper.mean_rotation_deg,
       m.paper.mean_yaw_deg);
  appendLine(s, "drift             %.4g m/min, %.4g deg/min (final %.4g m, %.4g deg)", m.drift.position_m_per_min,
       m.drift.rotation_deg_per_min, m.drift.final_position_m, m.drift.final_rotation_deg);
  if (m.nees.available)
    appendLine(s, "NEES              pose %.3f (6), position %.3f (3), orientation %.3f (3); %.1f %% in 95 %% bounds",
         m.nees.mean_pose, m.nees.mean_position, m.nees.mean_orientation, 100.0 * m.nees.share_in_bounds);
  else
    appendLine(s, "NEES              n/a (no covariance)");
  if (m.rtf.available)
    appendLine(s, "real-time factor  median %.3f, max %.3f, overall %.3f (%.3g events/s)", m.rtf.median, m.rtf.max,
         m.rtf.overall, m.rtf.mean_event_rate_hz);
  else
    appendLine(s, "real-time factor  n/a (no timing.txt)");
  if (m.rtf.available && m.rtf.features_known)
    appendLine(s, "RTF per feature   median %.3g (median %.1f features tracked)", m.rtf.median_per_feature,
         m.rtf.median_features);
  appendLine(s, "divergence        %s (max error/bound %.3g)", m.divergence.diverged ? m.divergence.cause.c_str() : "no",
       m.divergence.max_ratio);
  return s;
}

std::string poseErrorsCsv(const Metrics& m) {
  std::string s =
      "t_s,distance_m,gt_x,gt_y,gt_z,es_x,es_y,es_z,position_m,rotation_deg,yaw_deg,gravity_deg,nees_position,"
      "nees_orientation,nees_pose\n";
  std::size_t n = 0;
  for (const auto& e : m.pose_errors) {
    io::appendSeconds(s, e.t_ns);
    for (double v : {e.distance_m, e.p_gt.x(), e.p_gt.y(), e.p_gt.z(), e.p_es.x(), e.p_es.y(), e.p_es.z(),
                     e.position_m, e.rotation_deg, e.yaw_deg, e.gravity_deg}) {
      s += ",";
      appendNumber(s, v);
    }
    while (n < m.nees.samples.size() && m.nees.samples[n].t_ns < e.t_ns) ++n;
    if (n < m.nees.samples.size() && m.nees.samples[n].t_ns == e.t_ns) {
      for (double v : {m.nees.samples[n].position, m.nees.samples[n].orientation, m.nees.samples[n].pose}) {
        s += ",";
        appendNumber(s, v);
      }
    } else {
      s += ",,,";
    }
    s += "\n";
  }
  return s;
}

std::string rtfCsv(const Metrics& m) {
  const bool features = m.rtf.features_known;
  std::string s = features ? "t_s,rtf,event_rate_hz,features,rtf_per_feature\n" : "t_s,rtf,event_rate_hz\n";
  for (const auto& r : m.rtf.samples) {
    appendNumber(s, r.t_s);
    s += ",";
    appendNumber(s, r.rtf);
    s += ",";
    appendNumber(s, r.event_rate_hz);
    if (features) {
      s += ",";
      appendNumber(s, r.features);
      s += ",";
      appendNumber(s, r.rtf_per_feature);  // empty where no feature was tracked
    }
    s += "\n";
  }
  return s;
}

}  // namespace evio::experiments

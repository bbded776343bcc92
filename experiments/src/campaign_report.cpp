#include "evio/experiments/campaign_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "evio/core/error.h"
#include "evio/core/io/text_scanner.h"
#include "evio/experiments/metrics_format.h"
#include "evio/experiments/nees.h"

namespace evio::experiments {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double number(const std::string& text) {
  double v = 0.0;
  return io::parseFiniteDouble(text, &v) ? v : kNaN;
}

/// Order of two sweep cells "k=v;k=v…": key by key, a value that parses as
/// a number by its value (n_e 500 before 2000 before 10000, 0.0005 before
/// 0.001 before 0.01), other values as text; the whole text breaks ties.
bool sweepLess(const std::string& a, const std::string& b) {
  const auto split = [](const std::string& s) {
    std::vector<std::pair<std::string, std::string>> kv;
    std::size_t start = 0;
    while (start <= s.size() && !s.empty()) {
      const std::size_t end = std::min(s.find(';', start), s.size());
      const std::string item = s.substr(start, end - start);
      const std::size_t eq = item.find('=');
      kv.emplace_back(item.substr(0, eq), eq == std::string::npos ? std::string() : item.substr(eq + 1));
      start = end + 1;
    }
    return kv;
  };
  const auto ka = split(a), kb = split(b);
  for (std::size_t i = 0; i < std::min(ka.size(), kb.size()); ++i) {
    if (ka[i].first != kb[i].first) return ka[i].first < kb[i].first;
    double va = 0.0, vb = 0.0;
    const bool na = io::parseFiniteDouble(ka[i].second, &va), nb = io::parseFiniteDouble(kb[i].second, &vb);
    if (na && nb && va != vb) return va < vb;
    if (na != nb) return na;  // numbers before text
    if (!na && ka[i].second != kb[i].second) return ka[i].second < kb[i].second;
  }
  if (ka.size() != kb.size()) return ka.size() < kb.size();
  return a < b;
}

std::string fixed(double v, int digits) {
  if (!std::isfinite(v)) return "–";
  char buf[48];
  std::snprintf(buf, sizeof(buf), "%.*f", digits, v);
  return buf;
}

std::string general(double v) {
  if (!std::isfinite(v)) return "";
  std::string s;
  io::appendDouble(s, v);
  return s;
}

std::string spreadText(const Spread& s, int digits) {
  if (s.count == 0) return "–";
  if (s.count == 1) return fixed(s.median, digits);
  return fixed(s.median, digits) + " [" + fixed(s.q1, digits) + ", " + fixed(s.q3, digits) + "]";
}

}  // namespace

Spread spreadOf(std::vector<double> values) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }),
               values.end());
  Spread s;
  s.count = values.size();
  if (values.empty()) {
    s.median = s.q1 = s.q3 = kNaN;
    return s;
  }
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double pos = q * static_cast<double>(values.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (pos - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  s.median = quantile(0.5);
  s.q1 = quantile(0.25);
  s.q3 = quantile(0.75);
  return s;
}

void SelfDiagnosisAgreement::count(const std::string& estimator_status, const std::string& truth_diverged) {
  if (truth_diverged != "true" && truth_diverged != "false") return;  // older results: no truth verdict
  const bool flagged = estimator_status == "degraded" || estimator_status == "diverged";
  if (!flagged && estimator_status != "ok") return;
  if (truth_diverged == "true") ++(flagged ? caught : missed);
  else ++(flagged ? false_alarms : quiet);
}

CampaignReport aggregateSummary(const std::vector<std::vector<std::string>>& rows) {
  require(!rows.empty(), "summary.csv: empty");
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < rows[0].size(); ++i) col[rows[0][i]] = i;
  for (const char* needed : {"job_id", "scenario", "method", "sweep", "seed", "done", "status"})
    require(col.count(needed) > 0, std::string("summary.csv: no column '") + needed + "'");
  CampaignReport report;
  std::map<std::string, std::size_t> index;
  struct Values {
    std::vector<double> mpe, mye, ate_p, ate_r, completion, rtf, nees;
  };
  std::vector<Values> values;
  for (std::size_t r = 1; r < rows.size(); ++r) {
    const auto& row = rows[r];
    const auto get = [&](const std::string& name) -> std::string {
      const auto it = col.find(name);
      return it == col.end() || it->second >= row.size() ? std::string() : row[it->second];
    };
    const std::string key = get("scenario") + "\n" + get("method") + "\n" + get("sweep");
    auto [it, added] = index.emplace(key, report.groups.size());
    if (added) {
      ReportGroup g;
      g.scenario = get("scenario");
      g.method = get("method");
      g.sweep = get("sweep");
      report.groups.push_back(g);
      values.emplace_back();
    }
    ReportGroup& g = report.groups[it->second];
    Values& v = values[it->second];
    ++report.jobs;
    ++g.runs;
    if (get("done") != "1") {
      ++g.pending;
      continue;
    }
    ++report.finished;
    const std::string status = get("status");
    if (status == "ok") ++g.ok;
    else if (status == "diverged") ++g.diverged;
    else ++g.failed;
    if (g.alignment.empty()) {
      const std::string a = get("alignment.describe");
      g.alignment = a.substr(0, a.find(" ("));
    }
    if (status != "failed") v.completion.push_back(number(get("completion.share")));
    if (status == "ok") {
      v.mpe.push_back(number(get("paper.mpe_percent")));
      v.mye.push_back(number(get("paper.mye_deg_per_m")));
      v.ate_p.push_back(number(get("ate.position_m.rmse")));
      v.ate_r.push_back(number(get("ate.rotation_deg.rmse")));
    }
    if (status != "failed") g.self_diagnosis.count(get("estimator_status"), get("divergence.truth_diverged"));
    if (get("nees.available") == "true") v.nees.push_back(number(get("nees.mean_pose")));
    if (get("rtf.available") == "true") {
      v.rtf.push_back(number(get("rtf.median")));
      g.rtf_max = std::max(g.rtf_max, number(get("rtf.max")));
    }
  }
  for (std::size_t i = 0; i < report.groups.size(); ++i) {
    ReportGroup& g = report.groups[i];
    const Values& v = values[i];
    g.mpe_percent = spreadOf(v.mpe);
    g.mye_deg_per_m = spreadOf(v.mye);
    g.ate_position_m = spreadOf(v.ate_p);
    g.ate_rotation_deg = spreadOf(v.ate_r);
    g.completion = spreadOf(v.completion);
    g.rtf_median = spreadOf(v.rtf);
    double sum = 0.0;
    for (double x : v.nees)
      if (std::isfinite(x)) {
        sum += x;
        ++g.nees_runs;
      }
    if (g.nees_runs > 0) {
      g.anees = sum / static_cast<double>(g.nees_runs);
      const auto [lo, hi] = neesBounds(6, static_cast<int>(g.nees_runs));
      g.anees_lower = lo;
      g.anees_upper = hi;
    } else {
      g.anees = g.anees_lower = g.anees_upper = kNaN;
    }
  }
  // Scenarios in order of first appearance; within one, by method and sweep
  // (sweep values in numeric order).
  std::map<std::string, std::size_t> scenario_order;
  for (const auto& g : report.groups) scenario_order.emplace(g.scenario, scenario_order.size());
  std::stable_sort(report.groups.begin(), report.groups.end(), [&](const ReportGroup& a, const ReportGroup& b) {
    const std::size_t sa = scenario_order[a.scenario], sb = scenario_order[b.scenario];
    if (sa != sb) return sa < sb;
    if (a.method != b.method) return a.method < b.method;
    return sweepLess(a.sweep, b.sweep);
  });
  return report;
}

std::string comparisonMarkdown(const CampaignReport& report) {
  std::vector<std::string> scenarios, methods;
  const auto add = [](std::vector<std::string>& v, const std::string& x) {
    if (std::find(v.begin(), v.end(), x) == v.end()) v.push_back(x);
  };
  for (const auto& g : report.groups) {
    if (!g.sweep.empty()) return "";  // sweeps have their own rows per value
    add(scenarios, g.scenario);
    add(methods, g.method);
  }
  if (methods.size() < 2) return "";
  const auto find = [&](const std::string& sc, const std::string& m) -> const ReportGroup* {
    for (const auto& g : report.groups)
      if (g.scenario == sc && g.method == m) return &g;
    return nullptr;
  };
  std::string s = "\n## Comparison\n\nMedian MPE [%] / MYE [deg/m] over the successful runs (successful / "
                  "finished runs); the last row is the mean over the scenarios of those medians, as the paper "
                  "averages its sequences (over the scenarios where the method has a successful run). "
                  "Where MPE is undefined (no distance travelled), the cell gives the median ATE RMSE.\n\n";
  s += "| scenario |";
  for (const auto& m : methods) s += " " + m + " |";
  s += "\n|---|";
  for (std::size_t i = 0; i < methods.size(); ++i) s += "---|";
  s += "\n";
  std::vector<double> mpe_sum(methods.size(), 0.0), mye_sum(methods.size(), 0.0);
  std::vector<std::size_t> n(methods.size(), 0);
  for (const auto& sc : scenarios) {
    s += "| " + sc + " |";
    for (std::size_t k = 0; k < methods.size(); ++k) {
      const ReportGroup* g = find(sc, methods[k]);
      if (!g) {
        s += " – |";
        continue;
      }
      const std::size_t finished = g->runs - g->pending;
      const std::string runs = " (" + std::to_string(g->ok) + " / " + std::to_string(finished) + ")";
      if (g->mpe_percent.count == 0) {  // no distance travelled (rotation only): the ATE instead
        if (g->ate_position_m.count == 0) s.append(" –").append(runs).append(" |");
        else
          s.append(" ATE ").append(fixed(g->ate_position_m.median, 3)).append(" m, ")
              .append(fixed(g->ate_rotation_deg.median, 2)).append("°").append(runs).append(" |");
        continue;
      }
      s.append(" ").append(fixed(g->mpe_percent.median, 2)).append(" / ");
      s.append(fixed(g->mye_deg_per_m.median, 3)).append(runs).append(" |");
      mpe_sum[k] += g->mpe_percent.median;
      mye_sum[k] += g->mye_deg_per_m.median;
      ++n[k];
    }
    s += "\n";
  }
  s += "| **average** |";
  for (std::size_t k = 0; k < methods.size(); ++k)
    s += n[k] ? " **" + fixed(mpe_sum[k] / static_cast<double>(n[k]), 2) + " / " +
                    fixed(mye_sum[k] / static_cast<double>(n[k]), 3) + "** (" + std::to_string(n[k]) + " scenarios) |"
              : " – |";
  return s + "\n";
}

std::string selfDiagnosisMarkdown(const CampaignReport& report) {
  std::string rows;
  for (const auto& g : report.groups) {
    const SelfDiagnosisAgreement& a = g.self_diagnosis;
    if (a.judged() == 0) continue;
    rows += "| " + g.scenario + " | " + g.method + " | " + (g.sweep.empty() ? "–" : g.sweep) + " | " +
            std::to_string(a.judged()) + " | " + std::to_string(a.caught) + " | " + std::to_string(a.missed) + " | " +
            std::to_string(a.false_alarms) + " | " + std::to_string(a.quiet) + " |\n";
  }
  if (rows.empty()) return "";
  return "\n## Self-diagnosis\n\nThe estimator's own verdict (status.yaml degraded or diverged, without ground "
         "truth) against the ground truth's (the divergence bound), over the runs that did not fail.\n\n"
         "| scenario | method | sweep | runs | caught | missed | false alarms | quiet |\n"
         "|---|---|---|---:|---:|---:|---:|---:|\n" +
         rows;
}

std::string reportMarkdown(const CampaignReport& report, const std::string& title,
                           const std::vector<std::string>& figures, const std::vector<std::string>& notes) {
  std::string s = "# " + title + "\n\n";
  s += std::to_string(report.finished) + " of " + std::to_string(report.jobs) +
       " jobs finished. Success = status ok (not diverged, not failed). Error statistics are over the "
       "successful runs: median [first quartile, third quartile]. ANEES: mean of the runs' average 6-dof pose "
       "NEES, with its two-sided 95 % χ² bounds for that many runs (consistent: inside).\n";
  s += comparisonMarkdown(report);
  std::vector<std::string> scenarios;
  for (const auto& g : report.groups)
    if (std::find(scenarios.begin(), scenarios.end(), g.scenario) == scenarios.end()) scenarios.push_back(g.scenario);
  for (const auto& sc : scenarios) {
    s += "\n## " + sc + "\n\n";
    std::string alignment;
    for (const auto& g : report.groups)
      if (g.scenario == sc && !g.alignment.empty()) alignment = g.alignment;
    if (!alignment.empty()) s += "Alignment: " + alignment + ".\n\n";
    s += "| method | sweep | runs | success | diverged | failed | MPE [%] | MYE [deg/m] | ATE [m] | ATE [deg] | "
         "completion | ANEES (6) | RTF median / max |\n";
    s += "|---|---|---:|---:|---:|---:|---|---|---|---|---|---|---|\n";
    for (const auto& g : report.groups) {
      if (g.scenario != sc) continue;
      std::string anees = "–";
      if (g.nees_runs > 0) {
        const bool inside = g.anees >= g.anees_lower && g.anees <= g.anees_upper;
        anees = fixed(g.anees, 2) + " [" + fixed(g.anees_lower, 2) + ", " + fixed(g.anees_upper, 2) + "]" +
                (inside ? "" : " ✗");
      }
      s += "| " + g.method + " | " + (g.sweep.empty() ? "–" : g.sweep) + " | " + std::to_string(g.runs) +
           (g.pending ? " (" + std::to_string(g.pending) + " pending)" : "") + " | " +
           fixed(100.0 * g.successRate(), 0) + " % | " + std::to_string(g.diverged) + " | " +
           std::to_string(g.failed) + " | " + spreadText(g.mpe_percent, 2) + " | " + spreadText(g.mye_deg_per_m, 3) +
           " | " + spreadText(g.ate_position_m, 3) + " | " + spreadText(g.ate_rotation_deg, 2) + " | " +
           spreadText(g.completion, 2) + " | " + anees + " | " +
           (g.rtf_median.count ? fixed(g.rtf_median.median, 2) + " / " + fixed(g.rtf_max, 2) : "–") + " |\n";
    }
  }
  s += selfDiagnosisMarkdown(report);
  if (!figures.empty()) {
    s += "\n## Figures\n\n";
    for (const auto& f : figures) s += "![" + f + "](" + f + ")\n\n";
  }
  if (!notes.empty()) {
    s += "\n## Notes\n\n";
    for (const auto& n : notes) s += "- " + n + "\n";
  }
  return s;
}

std::string reportCsv(const CampaignReport& report) {
  std::string s =
      "scenario,method,sweep,runs,ok,diverged,failed,pending,success_rate,alignment,mpe_percent_median,"
      "mpe_percent_q1,mpe_percent_q3,mye_deg_per_m_median,ate_position_m_median,ate_rotation_deg_median,"
      "completion_median,nees_runs,anees,anees_lower_95,anees_upper_95,rtf_median,rtf_max\n";
  for (const auto& g : report.groups) {
    const std::vector<std::string> fields = {g.scenario,
                                             g.method,
                                             g.sweep,
                                             std::to_string(g.runs),
                                             std::to_string(g.ok),
                                             std::to_string(g.diverged),
                                             std::to_string(g.failed),
                                             std::to_string(g.pending),
                                             general(g.successRate()),
                                             g.alignment,
                                             general(g.mpe_percent.median),
                                             general(g.mpe_percent.q1),
                                             general(g.mpe_percent.q3),
                                             general(g.mye_deg_per_m.median),
                                             general(g.ate_position_m.median),
                                             general(g.ate_rotation_deg.median),
                                             general(g.completion.median),
                                             std::to_string(g.nees_runs),
                                             general(g.anees),
                                             general(g.anees_lower),
                                             general(g.anees_upper),
                                             general(g.rtf_median.median),
                                             g.rtf_median.count ? general(g.rtf_max) : ""};
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (i > 0) s += ',';
      s += csvField(fields[i]);
    }
    s += '\n';
  }
  return s;
}

}  // namespace evio::experiments

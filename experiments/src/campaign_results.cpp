#include "evio/experiments/campaign_results.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/experiments/campaign_runner.h"
#include "evio/experiments/json_value.h"
#include "evio/experiments/metrics_format.h"

namespace evio::experiments {

namespace fs = std::filesystem;

namespace {

bool keepColumn(const std::string& key) {
  if (key == "format" || key == "status" || key == "cause") return false;  // status/cause have fixed columns
  if (key.rfind("inputs.", 0) == 0) return false;
  const std::string tag = ".alignment";
  return !(key.size() > tag.size() && key.compare(key.size() - tag.size(), tag.size(), tag) == 0);
}

}  // namespace

std::string summaryCsv(const Campaign& c, const std::vector<Job>& jobs_in, const std::string& results) {
  std::vector<const Job*> jobs;
  for (const auto& j : jobs_in) jobs.push_back(&j);
  std::sort(jobs.begin(), jobs.end(), [](const Job* a, const Job* b) { return a->id < b->id; });

  std::vector<std::string> columns;
  std::set<std::string> known;
  std::vector<std::map<std::string, std::string>> rows(jobs.size());
  std::vector<bool> done(jobs.size(), false);
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const fs::path metrics = fs::path(jobFolder(results, *jobs[i])) / "metrics.json";
    if (!fs::is_regular_file(metrics)) continue;
    done[i] = true;
    const JsonValue m = parseJson(io::readFile(metrics.string()), metrics.string());
    std::vector<std::pair<std::string, std::string>> flat;
    m.flatten(flat);
    for (const auto& [k, v] : flat) {
      rows[i][k] = v;
      if (keepColumn(k) && known.insert(k).second) columns.push_back(k);
    }
  }
  std::string s = "job_id,scenario,method,sweep,seed,done,status,cause";
  const auto field = [&s](const std::string& text) {
    s += ',';
    s += csvField(text);
  };
  for (const auto& k : columns) field(k);
  s += '\n';
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const Job& j = *jobs[i];
    s += csvField(j.id);
    field(c.scenarios[j.scenario].name);
    field(c.methods[j.method].name);
    field(overridesText(j.sweep));
    field(std::to_string(j.seed));
    field(done[i] ? "1" : "0");
    const auto get = [&](const std::string& k) {
      const auto it = rows[i].find(k);
      return it == rows[i].end() ? std::string() : it->second;
    };
    field(get("status"));
    field(get("cause"));
    for (const auto& k : columns) field(get(k));
    s += '\n';
  }
  return s;
}

void writeSummary(const Campaign& campaign, const std::vector<Job>& jobs, const std::string& results) {
  io::writeFileAtomic((fs::path(results) / "summary.csv").string(), summaryCsv(campaign, jobs, results));
}

CollectReport collectResults(const Campaign& c, const std::vector<Job>& jobs, const std::string& results,
                             const std::vector<std::string>& from) {
  CollectReport r;
  r.jobs = jobs.size();
  fs::create_directories(fs::path(results) / "jobs");
  fs::create_directories(fs::path(results) / "staging");
  for (const Job& j : jobs) {
    if (!jobDone(results, j)) {
      for (const auto& other : from) {
        const fs::path src = fs::path(other) / "jobs" / j.id;
        if (!fs::is_regular_file(src / "metrics.json")) continue;
        const fs::path tmp = fs::path(results) / "staging" / (j.id + ".collect." + hostName() + "." +
                                                              std::to_string(::getpid()) + ".0");
        fs::remove_all(tmp);
        fs::copy(src, tmp, fs::copy_options::recursive);
        std::error_code ec;
        fs::rename(tmp, fs::path(jobFolder(results, j)), ec);
        if (ec) fs::remove_all(tmp);
        else ++r.merged;
        break;
      }
    }
    if (!jobDone(results, j)) {
      r.missing.push_back(j.id);
      continue;
    }
    ++r.done;
    if (!jobDone(results, j, /*retry_failed=*/true)) ++r.failed;
  }
  writeSummary(c, jobs, results);
  return r;
}

std::vector<std::vector<std::string>> parseCsv(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::vector<std::string> row;
  std::string field;
  bool quoted = false, any = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (quoted) {
      if (ch == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (ch == '"') {
        quoted = false;
      } else {
        field += ch;
      }
      continue;
    }
    if (ch == '"') {
      quoted = true;
      any = true;
    } else if (ch == ',') {
      row.push_back(std::move(field));
      field.clear();
      any = true;
    } else if (ch == '\n' || ch == '\r') {
      if (ch == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
      if (any || !field.empty()) {
        row.push_back(std::move(field));
        rows.push_back(std::move(row));
      }
      row.clear();
      field.clear();
      any = false;
    } else {
      field += ch;
      any = true;
    }
  }
  if (quoted) throw Error("CSV: unterminated quoted field");
  if (any || !field.empty()) {
    row.push_back(std::move(field));
    rows.push_back(std::move(row));
  }
  return rows;
}

}  // namespace evio::experiments

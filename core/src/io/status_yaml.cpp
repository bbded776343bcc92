#include "evio/core/io/status_yaml.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/text_scanner.h"

namespace evio::io {

namespace {

using config::Document;
using config::scalarAs;
using config::throwAt;

TimeNs timeAt(const Document& doc, const YAML::Node& node, const std::string& key) {
  const double t_s = scalarAs<double>(doc, node, key);
  if (!std::isfinite(t_s) || std::fabs(t_s) > 9e9) throwAt(doc, node, key, "must be a finite time in seconds");
  return secondsToNs(t_s);
}

void validate(const EstimateStatus& s, const std::string& where) {
  if (!s.ok() && !s.t_ns) throw Error(where + ": time_s: required when status is not ok");
  if (s.cause.find('\n') != std::string::npos) throw Error(where + ": cause: must be one line");
}

}  // namespace

std::string_view estimateStatusName(EstimateStatus::Code code) {
  switch (code) {
    case EstimateStatus::Code::kOk: return "ok";
    case EstimateStatus::Code::kDegraded: return "degraded";
    case EstimateStatus::Code::kDiverged: return "diverged";
    case EstimateStatus::Code::kFailed: return "failed";
  }
  return "failed";
}

EstimateStatus::Code parseEstimateStatusName(std::string_view name) {
  if (name == "ok") return EstimateStatus::Code::kOk;
  if (name == "degraded") return EstimateStatus::Code::kDegraded;
  if (name == "diverged") return EstimateStatus::Code::kDiverged;
  if (name == "failed") return EstimateStatus::Code::kFailed;
  throw Error("status: must be ok, degraded, diverged or failed (got '" + std::string(name) + "')");
}

EstimateStatus parseStatusYaml(const std::string& text, const std::string& name) {
  const Document doc = config::loadString(text, name);
  const YAML::Node& root = doc.root;
  if (!root.IsMap()) throwAt(doc, root, "<top level>", "expected a map");
  const std::set<std::string> known = {"status", "time_s", "cause", "initialization_time_s"};
  std::set<std::string> seen;
  for (auto it = root.begin(); it != root.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
    if (!known.count(key))
      throwAt(doc, it->first, key, "unknown key (known keys: status, time_s, cause, initialization_time_s)");
    if (!seen.insert(key).second) throwAt(doc, it->first, key, "duplicate key");
  }
  EstimateStatus s;
  const YAML::Node status = root["status"];
  if (!status.IsDefined() || status.IsNull()) throwAt(doc, root, "status", "missing required key 'status'");
  try {
    s.code = parseEstimateStatusName(scalarAs<std::string>(doc, status, "status"));
  } catch (const Error&) {
    throwAt(doc, status, "status", "must be ok, degraded, diverged or failed");
  }
  if (const YAML::Node t = root["time_s"]; t.IsDefined() && !t.IsNull()) s.t_ns = timeAt(doc, t, "time_s");
  if (const YAML::Node c = root["cause"]; c.IsDefined() && !c.IsNull()) s.cause = scalarAs<std::string>(doc, c, "cause");
  if (const YAML::Node t = root["initialization_time_s"]; t.IsDefined() && !t.IsNull())
    s.initialization_t_ns = timeAt(doc, t, "initialization_time_s");
  validate(s, name);
  return s;
}

EstimateStatus readStatusYaml(const std::string& path) { return parseStatusYaml(readFile(path), path); }

std::string formatStatusYaml(const EstimateStatus& s) {
  validate(s, "status.yaml");
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "status" << YAML::Value << std::string(estimateStatusName(s.code));
  if (s.t_ns) {
    std::string t;
    appendSeconds(t, *s.t_ns);
    out << YAML::Key << "time_s" << YAML::Value << t;
  }
  out << YAML::Key << "cause" << YAML::Value << YAML::DoubleQuoted << s.cause;
  if (s.initialization_t_ns) {
    std::string t;
    appendSeconds(t, *s.initialization_t_ns);
    out << YAML::Key << "initialization_time_s" << YAML::Value << t;
  }
  out << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

void writeStatusYaml(const std::string& path, const EstimateStatus& status) {
  writeFileAtomic(path, formatStatusYaml(status));
}

}  // namespace evio::io

#include "evio/experiments/campaign.h"

#include <yaml-cpp/yaml.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <set>

#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/experiments/trajectory_metrics.h"

namespace evio::experiments {

namespace {

namespace fs = std::filesystem;
using config::Document;
using config::scalarAs;
using config::throwAt;

const std::set<std::string> kPlaceholders = {"evio",     "bin",      "campaign_dir", "scenario", "scenario_file",
                                             "method",   "seed",     "sequence",     "job",      "simulate_set",
                                             "estimate_set", "evaluate_set", "estimator_config", "method_option"};

/// Checks a map's keys against `allowed` (unknown and duplicate keys are errors).
void checkKeys(const Document& doc, const YAML::Node& node, const std::string& path,
               const std::set<std::string>& allowed) {
  if (!node.IsMap()) throwAt(doc, node, path.empty() ? "<top level>" : path, "expected a map");
  std::set<std::string> seen;
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
    const std::string where = path.empty() ? key : path + "." + key;
    if (!allowed.count(key)) {
      std::string known;
      for (const auto& k : allowed) known += (known.empty() ? "" : ", ") + k;
      throwAt(doc, it->first, where, "unknown key (known keys: " + known + ")");
    }
    if (!seen.insert(key).second) throwAt(doc, it->first, where, "duplicate key");
  }
}

YAML::Node optional(const YAML::Node& map, const char* key) {
  const YAML::Node v = map[key];
  return v.IsDefined() && !v.IsNull() ? v : YAML::Node(YAML::NodeType::Undefined);
}

std::string valueText(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  YAML::Emitter out;
  out << YAML::Flow << node;
  return out.c_str();
}

bool validName(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (char c : name)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-')) return false;
  return true;
}

std::string name(const Document& doc, const YAML::Node& node, const std::string& path) {
  const std::string n = scalarAs<std::string>(doc, node, path);
  if (!validName(n)) throwAt(doc, node, path, "names use only letters, digits, '_' and '-' (got '" + n + "')");
  return n;
}

/// Flattens a map of overrides: nested maps become dotted keys.
void flattenOverrides(const Document& doc, const YAML::Node& node, const std::string& path, const std::string& prefix,
                      Overrides& out) {
  if (!node.IsMap()) throwAt(doc, node, path, "expected a map of key: value overrides");
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = prefix.empty() ? it->first.Scalar() : prefix + "." + it->first.Scalar();
    if (it->second.IsMap())
      flattenOverrides(doc, it->second, path + "." + it->first.Scalar(), key, out);
    else
      out.emplace_back(key, valueText(it->second));
  }
}

std::string absolute(const std::string& dir, const std::string& path) {
  return fs::weakly_canonical(fs::path(dir) / path).string();
}

/// The file a key names (relative to the campaign's folder), which must exist.
std::string existingFile(const Document& doc, const YAML::Node& node, const std::string& dir, const std::string& path) {
  const std::string file = absolute(dir, scalarAs<std::string>(doc, node, path));
  if (!fs::is_regular_file(file)) throwAt(doc, node, path, "no such file: " + file);
  return file;
}

CampaignStep step(const Document& doc, const YAML::Node& steps, const char* key, std::vector<std::string> fallback) {
  CampaignStep s;
  s.command = std::move(fallback);
  const YAML::Node node = optional(steps, key);
  if (!node.IsDefined()) return s;
  const std::string path = std::string("steps.") + key;
  checkKeys(doc, node, path, {"command", "timeout_s"});
  if (const YAML::Node c = optional(node, "command"); c.IsDefined()) {
    if (!c.IsSequence() || c.size() == 0) throwAt(doc, c, path + ".command", "expected a non-empty list of arguments");
    s.command.clear();
    for (std::size_t i = 0; i < c.size(); ++i)
      s.command.push_back(scalarAs<std::string>(doc, c[i], path + ".command[" + std::to_string(i) + "]"));
  }
  if (const YAML::Node t = optional(node, "timeout_s"); t.IsDefined()) {
    s.timeout_s = scalarAs<double>(doc, t, path + ".timeout_s");
    if (!(s.timeout_s >= 0.0)) throwAt(doc, t, path + ".timeout_s", "must be >= 0");
  }
  // "{name}" with a lower-case identifier is a placeholder and must be known;
  // other braces (JSON in a shell one-liner) are left alone.
  for (const auto& arg : s.command) {
    for (std::size_t open = arg.find('{'); open != std::string::npos; open = arg.find('{', open + 1)) {
      std::size_t end = open + 1;
      while (end < arg.size() && (std::islower(static_cast<unsigned char>(arg[end])) ||
                                  std::isdigit(static_cast<unsigned char>(arg[end])) || arg[end] == '_'))
        ++end;
      if (end == open + 1 || end >= arg.size() || arg[end] != '}') continue;
      const std::string ph = arg.substr(open + 1, end - open - 1);
      if (!kPlaceholders.count(ph))
        throwAt(doc, node, path + ".command", "unknown placeholder '{" + ph + "}' in '" + arg + "'");
    }
  }
  return s;
}

}  // namespace

std::uint64_t fnv1a64(const std::string& text) {
  std::uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ull;
  }
  return h;
}

std::string overridesText(const Overrides& overrides) {
  std::string s;
  for (const auto& [k, v] : overrides) s += (s.empty() ? "" : ";") + k + "=" + v;
  return s;
}

Campaign loadCampaign(const std::string& path, const std::vector<std::string>& overrides) {
  Document doc = config::loadFile(path);
  for (const auto& o : overrides) config::applyOverride(doc, o);
  const YAML::Node root = doc.root;
  checkKeys(doc, root, "",
            {"name", "seeds", "scenarios", "methods", "sweeps", "evaluate", "cache", "estimator_config", "steps",
             "slurm"});
  Campaign c;
  c.file = fs::absolute(path).lexically_normal().string();
  c.dir = fs::path(c.file).parent_path().string();
  try {
    c.name = name(doc, root["name"], "name");

    const YAML::Node seeds = root["seeds"];
    if (seeds.IsSequence()) {
      for (std::size_t i = 0; i < seeds.size(); ++i)
        c.seeds.push_back(scalarAs<std::uint64_t>(doc, seeds[i], "seeds[" + std::to_string(i) + "]"));
    } else if (seeds.IsMap()) {
      checkKeys(doc, seeds, "seeds", {"first", "count"});
      const auto first = scalarAs<std::uint64_t>(doc, seeds["first"], "seeds.first");
      const auto count = scalarAs<std::uint64_t>(doc, seeds["count"], "seeds.count");
      if (count > 100000) throwAt(doc, seeds, "seeds.count", "at most 100000");
      for (std::uint64_t i = 0; i < count; ++i) c.seeds.push_back(first + i);
    } else {
      throwAt(doc, seeds, "seeds", "expected a list of seeds or {first, count}");
    }
    if (c.seeds.empty()) throwAt(doc, seeds, "seeds", "no seeds");
    if (std::set<std::uint64_t>(c.seeds.begin(), c.seeds.end()).size() != c.seeds.size())
      throwAt(doc, seeds, "seeds", "duplicate seed");

    const YAML::Node scenarios = root["scenarios"];
    if (!scenarios.IsSequence() || scenarios.size() == 0)
      throwAt(doc, scenarios, "scenarios", "expected a non-empty list");
    std::set<std::string> names;
    for (std::size_t i = 0; i < scenarios.size(); ++i) {
      const std::string p = "scenarios[" + std::to_string(i) + "]";
      const YAML::Node s = scenarios[i];
      checkKeys(doc, s, p, {"name", "file", "sequence", "set", "estimate_set", "estimator_config"});
      CampaignScenario sc;
      sc.name = name(doc, s["name"], p + ".name");
      if (!names.insert(sc.name).second) throwAt(doc, s["name"], p + ".name", "duplicate scenario name");
      const YAML::Node file = optional(s, "file"), seq = optional(s, "sequence");
      if (file.IsDefined() == seq.IsDefined()) throwAt(doc, s, p, "give exactly one of 'file' and 'sequence'");
      if (file.IsDefined()) sc.file = absolute(c.dir, scalarAs<std::string>(doc, file, p + ".file"));
      if (seq.IsDefined()) sc.sequence = absolute(c.dir, scalarAs<std::string>(doc, seq, p + ".sequence"));
      if (const YAML::Node set = optional(s, "set"); set.IsDefined()) {
        if (seq.IsDefined()) throwAt(doc, set, p + ".set", "a recorded sequence takes no simulate overrides");
        flattenOverrides(doc, set, p + ".set", "", sc.set);
      }
      if (const YAML::Node set = optional(s, "estimate_set"); set.IsDefined())
        flattenOverrides(doc, set, p + ".estimate_set", "", sc.estimate_set);
      if (const YAML::Node ec = optional(s, "estimator_config"); ec.IsDefined())
        sc.estimator_config = existingFile(doc, ec, c.dir, p + ".estimator_config");
      c.scenarios.push_back(sc);
    }

    const YAML::Node methods = root["methods"];
    if (!methods.IsSequence() || methods.size() == 0) throwAt(doc, methods, "methods", "expected a non-empty list");
    names.clear();
    for (std::size_t i = 0; i < methods.size(); ++i) {
      const std::string p = "methods[" + std::to_string(i) + "]";
      const YAML::Node m = methods[i];
      CampaignMethod me;
      if (m.IsScalar()) {
        me.name = name(doc, m, p);
      } else {
        checkKeys(doc, m, p, {"name", "set"});
        me.name = name(doc, m["name"], p + ".name");
        if (const YAML::Node set = optional(m, "set"); set.IsDefined()) flattenOverrides(doc, set, p + ".set", "", me.set);
      }
      if (!names.insert(me.name).second) throwAt(doc, m, p, "duplicate method name '" + me.name + "'");
      c.methods.push_back(me);
    }

    if (const YAML::Node sweeps = optional(root, "sweeps"); sweeps.IsDefined()) {
      if (!sweeps.IsSequence()) throwAt(doc, sweeps, "sweeps", "expected a list of {key, values, step}");
      for (std::size_t i = 0; i < sweeps.size(); ++i) {
        const std::string p = "sweeps[" + std::to_string(i) + "]";
        checkKeys(doc, sweeps[i], p, {"key", "values", "step"});
        SweepAxis a;
        a.key = scalarAs<std::string>(doc, sweeps[i]["key"], p + ".key");
        if (const YAML::Node st = optional(sweeps[i], "step"); st.IsDefined()) {
          a.step = scalarAs<std::string>(doc, st, p + ".step");
          if (a.step != "simulate" && a.step != "estimate" && a.step != "evaluate")
            throwAt(doc, st, p + ".step", "must be simulate, estimate or evaluate");
        }
        const YAML::Node values = sweeps[i]["values"];
        if (!values.IsSequence() || values.size() == 0) throwAt(doc, values, p + ".values", "expected a non-empty list");
        for (std::size_t k = 0; k < values.size(); ++k) a.values.push_back(valueText(values[k]));
        c.sweeps.push_back(a);
      }
    }

    if (const YAML::Node ev = optional(root, "evaluate"); ev.IsDefined()) {
      EvaluationOptions check;
      config::fill(doc, "evaluate", check);  // file:line errors for bad options
      flattenOverrides(doc, ev, "evaluate", "", c.evaluate);
    }
    if (const YAML::Node cache = optional(root, "cache"); cache.IsDefined())
      c.cache = absolute(c.dir, scalarAs<std::string>(doc, cache, "cache"));
    if (const YAML::Node ec = optional(root, "estimator_config"); ec.IsDefined())
      c.estimator_config = existingFile(doc, ec, c.dir, "estimator_config");

    YAML::Node steps = optional(root, "steps");
    if (steps.IsDefined()) checkKeys(doc, steps, "steps", {"simulate", "estimate", "evaluate"});
    else steps = YAML::Node(YAML::NodeType::Map);
    c.simulate = step(doc, steps, "simulate",
                      {"{evio}", "simulate", "{scenario_file}", "-o", "{sequence}", "-q", "--set", "seed={seed}",
                       "{simulate_set}"});
    c.estimate = step(doc, steps, "estimate",
                      {"{evio}", "estimate", "{sequence}", "{estimator_config}", "{method_option}", "--init", "groundtruth",
                       "-o", "estimate",
                       "-q", "--set", "seed={seed}", "{estimate_set}"});
    c.evaluate_step = step(doc, steps, "evaluate",
                           {"{evio}", "evaluate", "estimate", "{sequence}", "-o", "metrics.json", "-q",
                            "{evaluate_set}"});

    if (const YAML::Node s = optional(root, "slurm"); s.IsDefined()) {
      checkKeys(doc, s, "slurm", {"time", "mem", "partition", "cpus_per_task", "jobs_per_task", "max_parallel", "extra"});
      SlurmSettings& sl = c.slurm;
      if (auto v = optional(s, "time"); v.IsDefined()) sl.time = scalarAs<std::string>(doc, v, "slurm.time");
      if (auto v = optional(s, "mem"); v.IsDefined()) sl.mem = scalarAs<std::string>(doc, v, "slurm.mem");
      if (auto v = optional(s, "partition"); v.IsDefined()) sl.partition = scalarAs<std::string>(doc, v, "slurm.partition");
      if (auto v = optional(s, "cpus_per_task"); v.IsDefined()) sl.cpus_per_task = scalarAs<int>(doc, v, "slurm.cpus_per_task");
      if (auto v = optional(s, "jobs_per_task"); v.IsDefined()) sl.jobs_per_task = scalarAs<int>(doc, v, "slurm.jobs_per_task");
      if (auto v = optional(s, "max_parallel"); v.IsDefined()) sl.max_parallel = scalarAs<int>(doc, v, "slurm.max_parallel");
      if (auto v = optional(s, "extra"); v.IsDefined()) {
        if (!v.IsSequence()) throwAt(doc, v, "slurm.extra", "expected a list of sbatch options");
        for (std::size_t i = 0; i < v.size(); ++i)
          sl.extra.push_back(scalarAs<std::string>(doc, v[i], "slurm.extra[" + std::to_string(i) + "]"));
      }
      if (sl.cpus_per_task < 1 || sl.cpus_per_task > 1024) throwAt(doc, s, "slurm.cpus_per_task", "must be in [1, 1024]");
      if (sl.jobs_per_task < 1 || sl.jobs_per_task > 100000)
        throwAt(doc, s, "slurm.jobs_per_task", "must be in [1, 100000]");
      if (sl.max_parallel < 0 || sl.max_parallel > 100000) throwAt(doc, s, "slurm.max_parallel", "must be in [0, 100000]");
    }
  } catch (const YAML::Exception& e) {
    throw Error::inFile(doc.file, e.mark.line + 1, "invalid campaign: " + e.msg);
  }
  return c;
}

std::vector<Job> expandJobs(const Campaign& c) {
  // Every combination of sweep values (the first axis varies slowest).
  std::vector<std::vector<std::size_t>> combos = {{}};
  for (const auto& axis : c.sweeps) {
    std::vector<std::vector<std::size_t>> next;
    for (const auto& combo : combos)
      for (std::size_t v = 0; v < axis.values.size(); ++v) {
        auto x = combo;
        x.push_back(v);
        next.push_back(x);
      }
    combos = std::move(next);
  }
  // Seed-major: a campaign stopped part-way has whole seeds (every cell with
  // the same number of runs); within a seed, neighbouring jobs run different
  // scenarios, so that parallel workers simulate different sequences.
  std::vector<Job> jobs;
  for (const std::uint64_t seed : c.seeds) {
    for (std::size_t m = 0; m < c.methods.size(); ++m) {
      for (const auto& combo : combos) {
        for (std::size_t s = 0; s < c.scenarios.size(); ++s) {
          Job j;
          j.scenario = s;
          j.method = m;
          j.seed = seed;
          j.simulate_set = c.scenarios[s].set;
          // The scenario's estimator settings first, so that a method may override them.
          j.estimate_set = c.scenarios[s].estimate_set;
          j.estimate_set.insert(j.estimate_set.end(), c.methods[m].set.begin(), c.methods[m].set.end());
          j.evaluate_set = c.evaluate;
          for (std::size_t a = 0; a < c.sweeps.size(); ++a) {
            const auto& axis = c.sweeps[a];
            const std::pair<std::string, std::string> kv(axis.key, axis.values[combo[a]]);
            j.sweep.push_back(kv);
            (axis.step == "simulate" ? j.simulate_set : axis.step == "estimate" ? j.estimate_set : j.evaluate_set)
                .push_back(kv);
          }
          const std::string& own_config = c.scenarios[s].estimator_config;
          j.estimator_config = own_config.empty() ? c.estimator_config : own_config;
          const std::string& sc = c.scenarios[s].name;
          // The estimator configuration is part of the identity by file name
          // (ids do not depend on where the checkout is): another parameter
          // set is another job, not one a resumed campaign would skip.
          const std::string identity =
              "scenario=" + sc + "|method=" + c.methods[m].name + "|seed=" + std::to_string(seed) +
              "|simulate=" + overridesText(j.simulate_set) + "|estimate=" + overridesText(j.estimate_set) +
              "|evaluate=" + overridesText(j.evaluate_set) +
              (j.estimator_config.empty() ? "" : "|estimator_config=" + fs::path(j.estimator_config).filename().string());
          char hash[24];
          std::snprintf(hash, sizeof(hash), "%08llx",
                        static_cast<unsigned long long>(fnv1a64(identity) & 0xffffffffull));
          j.id = sc + "." + c.methods[m].name + ".s" + std::to_string(seed) + "." + hash;
          if (c.scenarios[s].sequence.empty()) {
            std::snprintf(hash, sizeof(hash), "%08llx",
                          static_cast<unsigned long long>(
                              fnv1a64(c.scenarios[s].file + "|" + overridesText(j.simulate_set)) & 0xffffffffull));
            j.sequence_key = sc + "." + hash + "/seed-" + std::to_string(seed);
          }
          jobs.push_back(std::move(j));
        }
      }
    }
  }
  return jobs;
}

}  // namespace evio::experiments

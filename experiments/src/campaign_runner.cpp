#include "evio/experiments/campaign_runner.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <csignal>
#include <ctime>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/staged_folder.h"
#include "evio/core/stopwatch.h"
#include "evio/experiments/child_process.h"
#include "evio/experiments/json_value.h"

namespace evio::experiments {

namespace fs = std::filesystem;

namespace {

/// State shared by the workers of one run (no globals: one per runCampaign).
struct RunContext {
  std::mutex mutex;
  std::map<std::string, std::shared_ptr<std::mutex>> sequence_locks;
  std::map<std::string, std::string> failed_sequences;  ///< key → cause, this run
  std::uint64_t counter = 0;

  std::shared_ptr<std::mutex> lockFor(const std::string& key) {
    std::lock_guard<std::mutex> lock(mutex);
    auto& m = sequence_locks[key];
    if (!m) m = std::make_shared<std::mutex>();
    return m;
  }
  std::string unique() {
    std::lock_guard<std::mutex> lock(mutex);
    return std::to_string(::getpid()) + "." + std::to_string(counter++);
  }
};

struct StepRecord {
  std::string name;
  std::vector<std::string> command;
  std::string result;
  double wall_s = 0.0;
};

std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (std::size_t pos = s.find(from); pos != std::string::npos; pos = s.find(from, pos + to.size()))
    s.replace(pos, from.size(), to);
  return s;
}

std::string cacheRoot(const Campaign& c, const std::string& results) {
  return c.cache.empty() ? (fs::path(results) / "sequences").string() : c.cache;
}

std::string nowIso() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  ::gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof(buf), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

/// Renames a finished folder into place; false when the target exists
/// already (another worker or node finished first), in which case `from` is removed.
bool publish(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (!ec) return true;
  if (fs::exists(to)) {
    fs::remove_all(from, ec);
    return false;
  }
  throw Error("cannot rename " + from.string() + " to " + to.string() + ": " + ec.message());
}

/// publish() while the SIGINT/SIGTERM handler keeps off `from` (it would
/// otherwise empty a folder that is being renamed into place).
bool publishClaimed(io::InterruptCleanup& cleanup, const fs::path& from, const fs::path& to) {
  cleanup.beginPublish();
  try {
    return publish(from, to);
  } catch (...) {
    cleanup.cancelPublish();
    throw;
  }
}

std::string seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f", s);
  return buf;
}

std::string jobYaml(const Campaign& c, const Job& job, const std::string& sequence, const JobOutcome& outcome,
                    const std::vector<StepRecord>& steps, const std::string& started) {
  YAML::Emitter out;
  out << YAML::BeginMap;
  out << YAML::Key << "id" << YAML::Value << job.id;
  out << YAML::Key << "campaign" << YAML::Value << c.name;
  out << YAML::Key << "scenario" << YAML::Value << c.scenarios[job.scenario].name;
  out << YAML::Key << "method" << YAML::Value << c.methods[job.method].name;
  out << YAML::Key << "seed" << YAML::Value << job.seed;
  out << YAML::Key << "sweep" << YAML::Value << YAML::DoubleQuoted << overridesText(job.sweep);
  out << YAML::Key << "simulate_set" << YAML::Value << YAML::DoubleQuoted << overridesText(job.simulate_set);
  out << YAML::Key << "estimate_set" << YAML::Value << YAML::DoubleQuoted << overridesText(job.estimate_set);
  out << YAML::Key << "evaluate_set" << YAML::Value << YAML::DoubleQuoted << overridesText(job.evaluate_set);
  out << YAML::Key << "estimator_config" << YAML::Value << job.estimator_config;
  out << YAML::Key << "sequence" << YAML::Value << sequence;
  out << YAML::Key << "status" << YAML::Value << outcome.status;
  out << YAML::Key << "cause" << YAML::Value << YAML::DoubleQuoted << outcome.cause;
  out << YAML::Key << "host" << YAML::Value << hostName();
  out << YAML::Key << "started" << YAML::Value << started;
  out << YAML::Key << "wall_s" << YAML::Value << seconds(outcome.wall_s);
  out << YAML::Key << "steps" << YAML::Value << YAML::BeginSeq;
  for (const auto& s : steps) {
    out << YAML::BeginMap;
    out << YAML::Key << "name" << YAML::Value << s.name;
    out << YAML::Key << "command" << YAML::Value << YAML::Flow << s.command;
    out << YAML::Key << "result" << YAML::Value << s.result;
    out << YAML::Key << "wall_s" << YAML::Value << seconds(s.wall_s);
    out << YAML::EndMap;
  }
  out << YAML::EndSeq << YAML::EndMap;
  return std::string(out.c_str()) + "\n";
}

std::string failedMetricsJson(const std::string& step, const std::string& cause) {
  JsonValue j = JsonValue::object();
  j.set("format", JsonValue::string("evio-metrics/1"));
  j.set("status", JsonValue::string("failed"));
  j.set("cause", JsonValue::string(cause));
  j.set("failed_step", JsonValue::string(step));
  return j.dump();
}

/// Makes sure the job's sequence exists; returns "" or why it does not.
std::string ensureSequence(const Campaign& c, const Job& job, const RunnerOptions& o, RunContext& ctx,
                           const std::map<std::string, std::string>& vars_in, const fs::path& staging,
                           std::vector<StepRecord>& steps) {
  const CampaignScenario& sc = c.scenarios[job.scenario];
  if (!sc.sequence.empty())
    return fs::is_directory(sc.sequence) ? "" : "sequence folder " + sc.sequence + " does not exist";
  const fs::path final_dir = fs::path(cacheRoot(c, o.results)) / job.sequence_key;
  if (fs::is_directory(final_dir)) return "";
  const auto lock_ptr = ctx.lockFor(job.sequence_key);
  std::lock_guard<std::mutex> lock(*lock_ptr);
  if (fs::is_directory(final_dir)) return "";
  {
    std::lock_guard<std::mutex> g(ctx.mutex);
    const auto it = ctx.failed_sequences.find(job.sequence_key);
    if (it != ctx.failed_sequences.end()) return it->second;
  }
  const fs::path tmp = final_dir.string() + ".tmp." + hostName() + "." + ctx.unique();
  fs::create_directories(final_dir.parent_path());
  fs::remove_all(tmp);
  // Removed on SIGINT/SIGTERM, with the staging folder of the `simulate`
  // child writing it ("<tmp>.staging.<child pid>"): the child dies by
  // PDEATHSIG without cleaning up.
  io::InterruptCleanup cleanup(tmp.string(), io::InterruptCleanup::Scope::kWithChildStaging);
  auto vars = vars_in;
  vars["sequence"] = tmp.string();
  StepRecord rec{"simulate", expandCommand(c, c.simulate, vars, job), "", 0.0};
  const ChildResult r = runChild(rec.command, staging.string(), (staging / "logs" / "simulate.log").string(),
                                 c.simulate.timeout_s);
  rec.result = r.describe();
  rec.wall_s = r.wall_s;
  steps.push_back(rec);
  if (!r.ok()) {
    std::error_code ec;
    fs::remove_all(tmp, ec);
    const std::string last = lastLineOf((staging / "logs" / "simulate.log").string());
    const std::string cause = "simulate: " + r.describe() + (last.empty() ? "" : ": " + last);
    std::lock_guard<std::mutex> g(ctx.mutex);
    ctx.failed_sequences[job.sequence_key] = cause;
    return cause;
  }
  publishClaimed(cleanup, tmp, final_dir);
  return "";
}

/// A finished job of the same scenario file, method, seed, simulate and
/// estimate settings and estimator configuration whose estimate step succeeded: its estimate is this
/// job's too (only the evaluation differs). Returns its folder or "".
fs::path estimateDonor(const fs::path& results, const Job& job, const std::string& method,
                       const std::string& scenario, const std::string& sequence) {
  const std::string prefix = scenario + "." + method + ".s" + std::to_string(job.seed) + ".";
  std::error_code ec;
  const fs::path jobs = results / "jobs";
  if (!fs::is_directory(jobs, ec)) return {};
  std::vector<fs::path> candidates;
  for (const auto& entry : fs::directory_iterator(jobs, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name != job.id) candidates.push_back(entry.path());
  }
  std::sort(candidates.begin(), candidates.end());  // the same donor whatever the directory order
  for (const fs::path& dir : candidates) {
    if (!fs::is_regular_file(dir / "estimate" / "trajectory.txt", ec) || !fs::is_regular_file(dir / "job.yaml", ec))
      continue;
    try {
      const YAML::Node y = YAML::LoadFile((dir / "job.yaml").string());
      if (y["simulate_set"].as<std::string>("") != overridesText(job.simulate_set) ||
          y["estimate_set"].as<std::string>("") != overridesText(job.estimate_set) ||
          y["estimator_config"].as<std::string>("") != job.estimator_config ||
          y["sequence"].as<std::string>("") != sequence)
        continue;
      for (const auto& step : y["steps"])
        if (step["name"].as<std::string>("") == "estimate") {
          const std::string result = step["result"].as<std::string>("");
          if (result == "exit code 0" || result.rfind("reused from ", 0) == 0) return dir;
        }
    } catch (const YAML::Exception&) {
      continue;  // a damaged job.yaml is no donor
    }
  }
  return {};
}

JobOutcome runJobIn(const Campaign& c, const Job& job, const RunnerOptions& o, RunContext& ctx) {
  const Stopwatch watch;
  const std::string started = nowIso();
  const fs::path results(o.results);
  const fs::path final_dir = results / "jobs" / job.id;
  const fs::path staging = results / "staging" / (job.id + "." + hostName() + "." + ctx.unique());
  fs::remove_all(staging);
  io::InterruptCleanup cleanup(staging.string());  // removed on SIGINT/SIGTERM
  fs::create_directories(staging / "logs");
  cleanup.confirmCreated();

  std::map<std::string, std::string> vars;
  vars["evio"] = o.evio_binary;
  vars["bin"] = fs::path(o.evio_binary).parent_path().string();
  vars["campaign_dir"] = c.dir;
  vars["scenario"] = c.scenarios[job.scenario].name;
  vars["scenario_file"] = c.scenarios[job.scenario].file;
  vars["method"] = c.methods[job.method].name;
  vars["seed"] = std::to_string(job.seed);
  vars["job"] = staging.string();
  vars["sequence"] = sequenceFolder(c, o.results, job);

  std::vector<StepRecord> steps;
  std::string failed_step, cause = ensureSequence(c, job, o, ctx, vars, staging, steps);
  if (!cause.empty()) failed_step = "simulate";
  for (const auto& [name, step] : {std::pair<const char*, const CampaignStep*>{"estimate", &c.estimate},
                                   std::pair<const char*, const CampaignStep*>{"evaluate", &c.evaluate_step}}) {
    if (!failed_step.empty()) break;
    const std::string log = (staging / "logs" / (std::string(name) + ".log")).string();
    StepRecord rec{name, expandCommand(c, *step, vars, job), "", 0.0};
    if (std::string(name) == "estimate") {
      // Only the evaluation changed since a finished job: re-score its estimate.
      const fs::path donor = estimateDonor(results, job, c.methods[job.method].name,
                                           c.scenarios[job.scenario].name, vars["sequence"]);
      std::error_code ec;
      if (!donor.empty()) fs::copy(donor / "estimate", staging / "estimate", fs::copy_options::recursive, ec);
      if (!donor.empty() && !ec) {
        fs::copy_file(donor / "logs" / "estimate.log", log, ec);  // the log is a courtesy
        rec.result = "reused from jobs/" + donor.filename().string();
        steps.push_back(rec);
        continue;
      }
      fs::remove_all(staging / "estimate", ec);  // a failed copy: estimate afresh
    }
    const ChildResult r = runChild(rec.command, staging.string(), log, step->timeout_s);
    rec.result = r.describe();
    rec.wall_s = r.wall_s;
    steps.push_back(rec);
    // `evio estimate` exits 3 after writing an estimate whose status is
    // failed: the evaluate step still scores it (the job's status: failed).
    const bool failed_estimate = std::string(name) == "estimate" && r.started && !r.timed_out && r.signal == 0 &&
                                 r.exit_code == 3 && fs::is_regular_file(staging / "estimate" / "status.yaml");
    if (!r.ok() && !failed_estimate) {
      const std::string last = lastLineOf(log);
      failed_step = name;
      cause = std::string(name) + ": " + r.describe() + (last.empty() ? "" : ": " + last);
    }
  }
  const fs::path metrics = staging / "metrics.json";
  if (failed_step.empty() && !fs::is_regular_file(metrics)) {
    failed_step = "evaluate";
    cause = "evaluate: the step wrote no metrics.json";
  }
  if (!failed_step.empty()) io::writeFileAtomic(metrics.string(), failedMetricsJson(failed_step, cause));

  JobOutcome outcome;
  outcome.id = job.id;
  JsonValue m;
  try {
    m = parseJson(io::readFile(metrics.string()), metrics.string());
  } catch (const Error& e) {  // an evaluate step that wrote garbage fails its job, not the campaign
    cause = std::string("evaluate: ") + e.what();
    io::writeFileAtomic(metrics.string(), failedMetricsJson("evaluate", cause));
    m = parseJson(io::readFile(metrics.string()), metrics.string());
  }
  const JsonValue* status = m.find("status");
  outcome.status = status && !status->text().empty() ? status->text() : "failed";
  if (const JsonValue* cs = m.find("cause")) outcome.cause = cs->text();
  outcome.wall_s = watch.seconds();
  io::writeFileAtomic((staging / "job.yaml").string(),
                      jobYaml(c, job, vars["sequence"], outcome, steps, started));
  fs::create_directories(final_dir.parent_path());
  if (o.retry_failed && fs::exists(final_dir)) {
    cleanup.beginPublish();
    try {
      io::publishFolder(staging.string(), final_dir.string());  // the failed job replaced whole, never mixed
    } catch (...) {
      cleanup.cancelPublish();
      throw;
    }
  } else {
    publishClaimed(cleanup, staging, final_dir);
  }
  cleanup.release();
  return outcome;
}

bool processAlive(long pid) { return pid > 0 && (::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM); }

/// "<anything>.<host>.<pid>.<n>" left by a dead process of this host?
bool staleName(const std::string& name, const std::string& host) {
  const std::size_t n_dot = name.rfind('.');
  if (n_dot == std::string::npos || n_dot == 0) return false;
  const std::size_t pid_dot = name.rfind('.', n_dot - 1);
  if (pid_dot == std::string::npos || pid_dot == 0) return false;
  const std::size_t host_dot = name.rfind('.', pid_dot - 1);
  if (host_dot == std::string::npos) return false;
  if (name.substr(host_dot + 1, pid_dot - host_dot - 1) != host) return false;
  const std::string pid_text = name.substr(pid_dot + 1, n_dot - pid_dot - 1);
  char* end = nullptr;
  const long pid = std::strtol(pid_text.c_str(), &end, 10);
  if (end == pid_text.c_str() || *end != '\0') return false;
  return !processAlive(pid);
}

/// The campaign's own name inside a child's leftover in the sequence cache:
/// "<x>.tmp.<host>.<pid>.<n>.staging.<child pid>" (what a `simulate` child
/// killed by PDEATHSIG leaves) gives "<x>.tmp.<host>.<pid>.<n>" when the child
/// is dead; any other name is returned as it is. A live child's folder gives
/// a name that staleName() rejects.
std::string campaignPart(const std::string& name) {
  const std::size_t at = name.rfind(".staging.");
  if (at == std::string::npos) return name;
  const std::string pid_text = name.substr(at + 9);
  if (pid_text.empty() || pid_text.size() > 12 || pid_text.find_first_not_of("0123456789") != std::string::npos)
    return name;
  if (processAlive(std::strtol(pid_text.c_str(), nullptr, 10))) return "";
  return name.substr(0, at);
}

}  // namespace

std::vector<std::string> expandCommand(const Campaign& c, const CampaignStep& step,
                                       const std::map<std::string, std::string>& vars, const Job& job) {
  std::vector<std::string> out;
  const auto sets = [&](const Overrides& o) {
    for (const auto& [k, v] : o) {
      out.emplace_back("--set");
      out.push_back(k + "=" + v);
    }
  };
  for (const auto& arg : step.command) {
    if (arg == "{simulate_set}") sets(job.simulate_set);
    else if (arg == "{estimate_set}") sets(job.estimate_set);
    else if (arg == "{evaluate_set}") sets(job.evaluate_set);
    else if (arg == "{estimator_config}") {
      if (!job.estimator_config.empty()) out.insert(out.end(), {"--config", job.estimator_config});
    } else if (arg == "{method_option}") {
      const bool sets_method = std::any_of(job.estimate_set.begin(), job.estimate_set.end(),
                                           [](const auto& kv) { return kv.first == "method"; });
      if (!sets_method) out.insert(out.end(), {"--method", c.methods[job.method].name});
    } else {
      std::string a = arg;
      for (const auto& [k, v] : vars) a = replaceAll(a, "{" + k + "}", v);
      out.push_back(a);
    }
  }
  return out;
}


std::string hostName() {
  char buf[256] = {};
  if (::gethostname(buf, sizeof(buf) - 1) != 0) return "host";
  std::string h = buf;
  for (char& ch : h)
    if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '_')) ch = '_';
  return h.empty() ? "host" : h;
}

std::string jobFolder(const std::string& results, const Job& job) {
  return (fs::path(results) / "jobs" / job.id).string();
}

bool jobDone(const std::string& results, const Job& job, bool retry_failed) {
  const fs::path metrics = fs::path(jobFolder(results, job)) / "metrics.json";
  if (!fs::is_regular_file(metrics)) return false;
  if (!retry_failed) return true;
  const JsonValue m = parseJson(io::readFile(metrics.string()), metrics.string());
  const JsonValue* status = m.find("status");
  return !(status && status->text() == "failed");
}

std::string sequenceFolder(const Campaign& c, const std::string& results, const Job& job) {
  const CampaignScenario& sc = c.scenarios[job.scenario];
  if (!sc.sequence.empty()) return sc.sequence;
  return (fs::path(cacheRoot(c, results)) / job.sequence_key).string();
}

JobOutcome runJob(const Campaign& campaign, const Job& job, const RunnerOptions& options) {
  RunContext ctx;
  return runJobIn(campaign, job, options, ctx);
}

std::size_t removeStaleStaging(const Campaign& c, const std::string& results) {
  const std::string host = hostName();
  std::size_t removed = 0;
  std::error_code ec;
  const fs::path staging = fs::path(results) / "staging";
  if (fs::is_directory(staging))
    for (const auto& e : fs::directory_iterator(staging, ec))
      if (staleName(e.path().filename().string(), host)) removed += fs::remove_all(e.path(), ec) > 0;
  const fs::path cache = cacheRoot(c, results);
  if (fs::is_directory(cache))
    for (const auto& scenario : fs::directory_iterator(cache, ec))
      if (scenario.is_directory())
        for (const auto& e : fs::directory_iterator(scenario.path(), ec)) {
          const std::string name = e.path().filename().string();
          if (name.find(".tmp.") != std::string::npos && staleName(campaignPart(name), host))
            removed += fs::remove_all(e.path(), ec) > 0;
        }
  return removed;
}

std::vector<JobOutcome> runCampaign(const Campaign& campaign, const std::vector<Job>& jobs,
                                    const RunnerOptions& options, const ProgressCallback& progress) {
  require(options.workers >= 1, "campaign: workers must be >= 1");
  require(!options.results.empty(), "campaign: no results folder");
  require(!options.evio_binary.empty(), "campaign: the evio binary is unknown");
  fs::create_directories(fs::path(options.results) / "jobs");
  fs::create_directories(fs::path(options.results) / "staging");
  removeStaleStaging(campaign, options.results);

  std::vector<JobOutcome> outcomes(jobs.size());
  std::vector<std::size_t> pending;
  CampaignProgress p;
  p.total = jobs.size();
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    if (jobDone(options.results, jobs[i], options.retry_failed)) {
      outcomes[i] = {jobs[i].id, "skipped", "", 0.0};
      ++p.skipped;
    } else {
      pending.push_back(i);
    }
  }
  std::mutex progress_mutex;
  if (progress) progress(p);

  RunContext ctx;
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::exception_ptr error;
  const auto worker = [&] {
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= pending.size() || stop) return;
      const std::size_t i = pending[k];
      {
        std::lock_guard<std::mutex> lock(progress_mutex);
        ++p.running;
      }
      try {
        outcomes[i] = runJobIn(campaign, jobs[i], options, ctx);
      } catch (...) {
        std::lock_guard<std::mutex> lock(progress_mutex);
        if (!error) error = std::current_exception();
        stop = true;
        --p.running;
        return;
      }
      std::lock_guard<std::mutex> lock(progress_mutex);
      --p.running;
      ++p.finished;
      if (outcomes[i].status == "failed") ++p.failed;
      p.last = &outcomes[i];
      if (progress) progress(p);
      p.last = nullptr;
    }
  };
  const int n = std::min<int>(options.workers, static_cast<int>(std::max<std::size_t>(pending.size(), 1)));
  std::vector<std::thread> threads;
  for (int t = 0; t < n; ++t) threads.emplace_back(worker);
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
  return outcomes;
}

}  // namespace evio::experiments

#include "evio/experiments/campaign.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>

#include <yaml-cpp/yaml.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/experiments/campaign_results.h"
#include "evio/experiments/campaign_runner.h"
#include "evio/experiments/child_process.h"
#include "evio/experiments/metrics_format.h"
#include "evio/experiments/slurm_script.h"
#include "error_of.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

namespace fs = std::filesystem;

using test::errorOf;

/// The estimate step's command recorded in a job's job.yaml, as one line
/// (arguments joined by spaces), or "" when the job has no estimate step.
std::string estimateCommandLine(const std::string& job_folder) {
  const YAML::Node y = YAML::LoadFile((fs::path(job_folder) / "job.yaml").string());
  std::string line;
  for (const auto& step : y["steps"]) {
    if (step["name"].as<std::string>() != "estimate") continue;
    for (const auto& arg : step["command"]) {
      if (!line.empty()) line += ' ';
      line += arg.as<std::string>();
    }
  }
  return line;
}

/// A campaign whose steps are shell one-liners: "simulate" writes the
/// sequence and counts itself in <dir>/simulations, "estimate" fails with
/// exit code 3 for method "broken", "evaluate" writes a metrics.json whose
/// number is the seed.
std::string shellCampaign(const test::TempDir& dir) {
  const std::string count = dir.file("simulations");
  return R"(name: unit
seeds: [1, 2, 3]
scenarios:
  - {name: a, file: a.yaml, set: {duration_s: 2}}
  - {name: b, file: b.yaml}
methods:
  - good
  - name: broken
    set: {fail: 1}
sweeps:
  - {key: k, values: [1, 2]}
steps:
  simulate:
    command: [/bin/sh, -c, "mkdir -p {sequence} && echo {scenario} {seed} > {sequence}/groundtruth.txt && echo x >> )" +
         count + R"("]
  estimate:
    command: [/bin/sh, -c, "mkdir estimate && test {method} = good || exit 3", "{estimate_set}"]
  evaluate:
    command: [/bin/sh, -c, "printf '{\"format\": \"evio-metrics/1\", \"status\": \"ok\", \"paper\": {\"mpe_percent\": {seed}}}' > metrics.json"]
)";
}

TEST(Campaign, ExpandsTheMatrixWithStableUniqueIds) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), shellCampaign(dir));
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  EXPECT_EQ(c.name, "unit");
  EXPECT_EQ(c.scenarios[0].file, dir.file("a.yaml"));
  const auto jobs = expandJobs(c);
  ASSERT_EQ(jobs.size(), 2u * 2u * 2u * 3u);  // scenarios × methods × sweep values × seeds
  std::set<std::string> ids, sequences;
  for (const auto& j : jobs) {
    ids.insert(j.id);
    sequences.insert(j.sequence_key);
  }
  EXPECT_EQ(ids.size(), jobs.size());
  EXPECT_EQ(sequences.size(), 6u);  // the sweep and the method do not touch the sequence
  // Seed-major order: the first 2 × 2 × 2 jobs are every cell of seed 1, so a
  // stopped campaign has whole seeds; neighbouring jobs need different sequences.
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(jobs[i].seed, 1u) << i;
  EXPECT_EQ(jobs[8].seed, 2u);
  EXPECT_NE(jobs[0].sequence_key, jobs[1].sequence_key);
  // The id is a readable prefix and a hash of everything that defines the job.
  EXPECT_EQ(jobs[0].id.rfind("a.good.s1.", 0), 0u);
  EXPECT_EQ(jobs[0].id, "a.good.s1.58f64657");
  EXPECT_EQ(overridesText(jobs[0].estimate_set), "k=1");
  EXPECT_EQ(overridesText(jobs[0].simulate_set), "duration_s=2");
  // Overrides from the command line apply before expansion.
  EXPECT_EQ(expandJobs(loadCampaign(dir.file("c.yaml"), {"seeds=[7]"})).size(), 8u);
  EXPECT_EQ(expandJobs(loadCampaign(dir.file("c.yaml"), {"seeds={first: 10, count: 5}"})).size(), 40u);
}

TEST(Campaign, ScenarioEstimateSettingsComeBeforeTheMethods) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), R"(name: tuned
seeds: [1]
scenarios:
  - {name: near, file: near.yaml}
  - {name: far, file: far.yaml, estimate_set: {backend: {slam_min_depth_m: 5}, sync.n_e: 9000}}
methods:
  - plain
  - name: fast
    set: {sync.n_e: 500}
)");
  const auto jobs = expandJobs(loadCampaign(dir.file("c.yaml")));
  ASSERT_EQ(jobs.size(), 4u);
  std::map<std::string, std::string> by_cell;
  for (const auto& j : jobs) by_cell[j.id.substr(0, j.id.find(".s1."))] = overridesText(j.estimate_set);
  EXPECT_EQ(by_cell["near.plain"], "");
  EXPECT_EQ(by_cell["near.fast"], "sync.n_e=500");
  // Applied in order, so the method's n_e wins over the scenario's.
  EXPECT_EQ(by_cell["far.plain"], "backend.slam_min_depth_m=5;sync.n_e=9000");
  EXPECT_EQ(by_cell["far.fast"], "backend.slam_min_depth_m=5;sync.n_e=9000;sync.n_e=500");
}

TEST(Campaign, RejectsBadFilesWithFileAndLine) {
  test::TempDir dir;
  const auto load = [&](const std::string& text) {
    io::writeFileAtomic(dir.file("bad.yaml"), text);
    return errorOf([&] { loadCampaign(dir.file("bad.yaml")); });
  };
  const std::string ok = "name: x\nseeds: [1]\nscenarios: [{name: s, file: s.yaml}]\nmethods: [m]\n";
  EXPECT_EQ(load(ok), "");
  EXPECT_NE(load(ok + "colour: red\n").find("bad.yaml:5"), std::string::npos);
  EXPECT_NE(load(ok + "evaluate: {alignment: {type: rigid}}\n").find("alignment.type"), std::string::npos);
  EXPECT_NE(load(ok + "steps: {estimate: {command: [x, \"{nope}\"]}}\n").find("{nope}"), std::string::npos);
  EXPECT_NE(load("name: x\nseeds: [1, 1]\nscenarios: [{name: s, file: s.yaml}]\nmethods: [m]\n").find("duplicate seed"),
            std::string::npos);
  EXPECT_NE(load("name: x\nseeds: [1]\nscenarios: [{name: s, file: s.yaml}]\nmethods: [m, m]\n").find("duplicate"),
            std::string::npos);
  EXPECT_NE(load("name: x\nseeds: [1]\nscenarios: [{name: s, file: a, sequence: b}]\nmethods: [m]\n").find("exactly one"),
            std::string::npos);
  EXPECT_NE(load("name: x y\nseeds: [1]\nscenarios: [{name: s, file: s.yaml}]\nmethods: [m]\n").find("name"),
            std::string::npos);
  EXPECT_NE(load("name: x\nseeds: []\nscenarios: [{name: s, file: s.yaml}]\nmethods: [m]\n").find("no seeds"),
            std::string::npos);
}

TEST(ChildProcess, ReportsExitCodesSignalsTimeoutsAndMissingPrograms) {
  test::TempDir dir;
  const std::string log = dir.file("log.txt");
  const ChildResult ok = runChild({"/bin/sh", "-c", "pwd; echo done"}, dir.path().string(), log, 0.0);
  EXPECT_TRUE(ok.ok());
  EXPECT_EQ(lastLineOf(log), "done");
  EXPECT_NE(io::readFile(log).find(dir.path().filename().string()), std::string::npos);  // ran in cwd
  const ChildResult code = runChild({"/bin/sh", "-c", "echo oops >&2; exit 3"}, "", log, 0.0);
  EXPECT_EQ(code.exit_code, 3);
  EXPECT_EQ(code.describe(), "exit code 3");
  EXPECT_EQ(lastLineOf(log), "oops");
  const ChildResult sig = runChild({"/bin/sh", "-c", "kill -SEGV $$"}, "", log, 0.0);
  EXPECT_EQ(sig.signal, SIGSEGV);
  EXPECT_FALSE(sig.ok());
  const ChildResult slow = runChild({"/bin/sh", "-c", "sleep 30"}, "", log, 0.3);
  EXPECT_TRUE(slow.timed_out);
  EXPECT_NE(slow.describe().find("timed out"), std::string::npos);
  const ChildResult missing = runChild({"/nonexistent/program"}, "", log, 0.0);
  EXPECT_FALSE(missing.started);
  EXPECT_NE(missing.describe().find("cannot execute"), std::string::npos);
}

TEST(CampaignRunner, RunsResumesCachesSequencesAndRecordsFailures) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), shellCampaign(dir));
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  const auto jobs = expandJobs(c);
  RunnerOptions o;
  o.results = dir.file("results");
  o.workers = 3;
  o.evio_binary = "/bin/true";
  std::size_t calls = 0;
  const auto outcomes = runCampaign(c, jobs, o, [&](const CampaignProgress& p) {
    ++calls;
    EXPECT_LE(p.finished, p.total);
  });
  EXPECT_EQ(calls, 1u + jobs.size());
  std::size_t ok = 0, failed = 0;
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    const bool broken = c.methods[jobs[i].method].name == "broken";
    EXPECT_EQ(outcomes[i].status, broken ? "failed" : "ok") << jobs[i].id;
    if (broken) {
      EXPECT_NE(outcomes[i].cause.find("estimate: exit code 3"), std::string::npos) << outcomes[i].cause;
    }
    (broken ? failed : ok) += 1;
    EXPECT_TRUE(jobDone(o.results, jobs[i]));
    EXPECT_TRUE(fs::is_regular_file(fs::path(jobFolder(o.results, jobs[i])) / "job.yaml"));
    EXPECT_TRUE(fs::is_regular_file(fs::path(jobFolder(o.results, jobs[i])) / "logs" / "estimate.log"));
  }
  EXPECT_EQ(ok, 12u);
  EXPECT_EQ(failed, 12u);
  // Each (scenario, seed) was simulated exactly once, whatever the workers did.
  const std::string sims = io::readFile(dir.file("simulations"));
  EXPECT_EQ(std::count(sims.begin(), sims.end(), '\n'), 6);
  EXPECT_TRUE(fs::is_empty(fs::path(o.results) / "staging"));

  // A second run skips everything; with retry_failed it re-runs only the failures.
  for (const auto& out : runCampaign(c, jobs, o)) EXPECT_EQ(out.status, "skipped");
  o.retry_failed = true;
  std::size_t rerun = 0;
  for (const auto& out : runCampaign(c, jobs, o)) rerun += out.status != "skipped";
  EXPECT_EQ(rerun, 12u);

  writeSummary(c, jobs, o.results);
  const auto rows = parseCsv(io::readFile(dir.file("results/summary.csv")));
  ASSERT_EQ(rows.size(), 1 + jobs.size());
  EXPECT_EQ(rows[0][0], "job_id");
  EXPECT_EQ(rows[0].back(), "paper.mpe_percent");
  for (std::size_t r = 1; r < rows.size(); ++r) {
    EXPECT_EQ(rows[r].size(), rows[0].size());
    EXPECT_LT(rows[r - 1][0], r > 1 ? rows[r][0] : "~");  // sorted by id
    if (rows[r][6] == "ok") {
      EXPECT_EQ(rows[r].back(), rows[r][4]);  // mpe = seed
    }
  }
}

TEST(CampaignRunner, DefaultEstimateCommandPassesTheEstimatorConfigAndTheMethod) {
  // estimator_config (relative to the campaign file) becomes --config <absolute
  // path>; --method <name> is passed unless the method's settings set
  // `method` themselves (a variant named for what it changes).
  test::TempDir dir;
  fs::create_directories(dir.file("tuning"));
  io::writeFileAtomic(dir.file("tuning/sim.yaml"), "sync: {n_e: 3200}\n");
  io::writeFileAtomic(dir.file("c.yaml"), R"(name: defaults
seeds: [1]
scenarios:
  - {name: a, file: a.yaml}
methods:
  - klt-vio
  - name: fewer_features
    set: {method: eklt-vio, frontend.eklt.max_features: 20}
estimator_config: tuning/sim.yaml
steps:
  simulate: {command: [/bin/sh, -c, "mkdir -p {sequence}"]}
)");
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  EXPECT_EQ(c.estimator_config, fs::path(dir.file("tuning/sim.yaml")).lexically_normal().string());
  RunnerOptions o;
  o.results = dir.file("results");
  o.workers = 1;
  o.evio_binary = "/bin/true";  // every step "succeeds" without output: the jobs fail at evaluate, commands recorded
  const auto jobs = expandJobs(c);
  (void)runCampaign(c, jobs, o);
  std::map<std::string, std::string> estimate_command;
  for (const auto& job : jobs) estimate_command[c.methods[job.method].name] = estimateCommandLine(jobFolder(o.results, job));
  const std::string seq = jobs[0].sequence_key;
  EXPECT_EQ(estimate_command["klt-vio"],
            "/bin/true estimate " + (fs::path(o.results) / "sequences" / seq).string() + " --config " +
                c.estimator_config + " --method klt-vio --init groundtruth -o estimate -q --set seed=1");
  EXPECT_EQ(estimate_command["fewer_features"],
            "/bin/true estimate " + (fs::path(o.results) / "sequences" / seq).string() + " --config " +
                c.estimator_config +
                " --init groundtruth -o estimate -q --set seed=1 --set method=eklt-vio "
                "--set frontend.eklt.max_features=20");
  // A missing configuration is an error at load time, naming the key.
  io::writeFileAtomic(dir.file("bad.yaml"), "name: x\nseeds: [1]\nscenarios: [{name: a, file: a.yaml}]\n"
                                            "methods: [klt-vio]\nestimator_config: nowhere.yaml\n");
  const std::string e = errorOf([&] { loadCampaign(dir.file("bad.yaml")); });
  EXPECT_NE(e.find("bad.yaml:5: estimator_config"), std::string::npos) << e;
}

TEST(CampaignRunner, AScenarioMayNameItsOwnEstimatorConfig) {
  // One parameter set per rig: a scenario's estimator_config replaces the
  // campaign's for that scenario's jobs only; the configuration's file name
  // is part of a job's identity.
  test::TempDir dir;
  fs::create_directories(dir.file("tuning"));
  io::writeFileAtomic(dir.file("tuning/indoor.yaml"), "sync: {n_e: 3200}\n");
  io::writeFileAtomic(dir.file("tuning/mars.yaml"), "backend: {slam_update_interval_s: 0.04}\n");
  const std::string head = R"(name: rigs
seeds: [1]
scenarios:
)";
  const std::string tail = R"(  - {name: poster, file: b.yaml}
methods: [klt-vio]
estimator_config: tuning/indoor.yaml
steps:
  simulate: {command: [/bin/sh, -c, "mkdir -p {sequence}"]}
)";
  io::writeFileAtomic(dir.file("own.yaml"), head + "  - {name: mars, file: a.yaml, estimator_config: tuning/mars.yaml}\n" + tail);
  io::writeFileAtomic(dir.file("shared.yaml"), head + "  - {name: mars, file: a.yaml}\n" + tail);
  const Campaign c = loadCampaign(dir.file("own.yaml"));
  const std::string indoor = fs::path(dir.file("tuning/indoor.yaml")).lexically_normal().string();
  const std::string mars = fs::path(dir.file("tuning/mars.yaml")).lexically_normal().string();
  EXPECT_EQ(c.scenarios[0].estimator_config, mars);
  EXPECT_EQ(c.scenarios[1].estimator_config, "");
  const auto jobs = expandJobs(c);
  ASSERT_EQ(jobs.size(), 2u);
  EXPECT_EQ(jobs[0].estimator_config, mars);
  EXPECT_EQ(jobs[1].estimator_config, indoor);
  const auto shared = expandJobs(loadCampaign(dir.file("shared.yaml")));
  EXPECT_NE(jobs[0].id, shared[0].id);  // another configuration: another job
  EXPECT_EQ(jobs[1].id, shared[1].id);  // the other scenario's jobs are unchanged
  // So is another campaign-wide configuration: a resumed campaign re-runs its jobs.
  io::writeFileAtomic(dir.file("tuning/indoor_v2.yaml"), "sync: {n_e: 3200}\n");
  const auto renamed = expandJobs(loadCampaign(dir.file("shared.yaml"), {"estimator_config=tuning/indoor_v2.yaml"}));
  EXPECT_NE(renamed[1].id, shared[1].id);

  RunnerOptions o;
  o.results = dir.file("results");
  o.workers = 1;
  o.evio_binary = "/bin/true";
  (void)runCampaign(c, jobs, o);
  for (const auto& job : jobs) {
    const YAML::Node y = YAML::LoadFile((fs::path(jobFolder(o.results, job)) / "job.yaml").string());
    EXPECT_EQ(y["estimator_config"].as<std::string>(), job.estimator_config);
    const std::string line = estimateCommandLine(jobFolder(o.results, job));
    EXPECT_NE(line.find(" --config " + job.estimator_config + " --method klt-vio "), std::string::npos) << line;
  }
  // A missing file is an error at load time naming the scenario's key and line.
  io::writeFileAtomic(dir.file("bad.yaml"), head + "  - {name: mars, file: a.yaml, estimator_config: none.yaml}\n" + tail);
  const std::string e = errorOf([&] { loadCampaign(dir.file("bad.yaml")); });
  EXPECT_NE(e.find("bad.yaml:4: scenarios[0].estimator_config: no such file"), std::string::npos) << e;
}

TEST(CampaignRunner, ReScoresAFinishedEstimateWhenOnlyTheEvaluationChanged) {
  test::TempDir dir;
  // estimate counts itself in <dir>/estimates; evaluate writes the alignment
  // window start it was given as the MPE.
  const std::string text = R"(name: rescore
seeds: [1, 2]
scenarios:
  - {name: a, file: a.yaml}
methods:
  - good
evaluate:
  alignment: {start_s: 3}
steps:
  simulate:
    command: [/bin/sh, -c, "mkdir -p {sequence} && echo x > {sequence}/groundtruth.txt"]
  estimate:
    command: [/bin/sh, -c, "echo x >> )" + dir.file("estimates") + R"( && mkdir estimate && echo {seed} > estimate/trajectory.txt"]
  evaluate:
    command: [/bin/sh, -c, "printf '{\"format\": \"evio-metrics/1\", \"status\": \"ok\", \"paper\": {\"mpe_percent\": %s}}' ${2#*=} > metrics.json", sh, "{evaluate_set}"]
)";
  io::writeFileAtomic(dir.file("c.yaml"), text);
  RunnerOptions o;
  o.results = dir.file("results");
  o.workers = 1;
  o.evio_binary = "/bin/true";
  const Campaign first = loadCampaign(dir.file("c.yaml"));
  for (const auto& out : runCampaign(first, expandJobs(first), o)) EXPECT_EQ(out.status, "ok") << out.cause;
  EXPECT_EQ(io::readFile(dir.file("estimates")), "x\nx\n");

  // Another alignment window: new jobs, scored again, estimated no more.
  const Campaign second = loadCampaign(dir.file("c.yaml"), {"evaluate.alignment.start_s=4"});
  const auto jobs = expandJobs(second);
  for (const auto& out : runCampaign(second, jobs, o)) EXPECT_EQ(out.status, "ok") << out.cause;
  EXPECT_EQ(io::readFile(dir.file("estimates")), "x\nx\n");
  for (const auto& job : jobs) {
    const fs::path folder = jobFolder(o.results, job);
    EXPECT_EQ(io::readFile((folder / "estimate" / "trajectory.txt").string()), std::to_string(job.seed) + "\n");
    EXPECT_NE(io::readFile((folder / "metrics.json").string()).find("\"mpe_percent\": 4"), std::string::npos);
    EXPECT_NE(io::readFile((folder / "job.yaml").string()).find("reused from jobs/a.good.s" + std::to_string(job.seed)),
              std::string::npos);
  }

  // Other estimate settings are a new estimate.
  const Campaign third = loadCampaign(dir.file("c.yaml"), {"methods=[{name: good, set: {k: 2}}]"});
  for (const auto& out : runCampaign(third, expandJobs(third), o)) EXPECT_EQ(out.status, "ok") << out.cause;
  EXPECT_EQ(io::readFile(dir.file("estimates")), "x\nx\nx\nx\n");
}

TEST(CampaignRunner, AnEvaluateStepThatWritesGarbageFailsItsJobNotTheCampaign) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), R"(name: garbage
seeds: [1]
scenarios:
  - {name: a, file: a.yaml}
methods:
  - good
steps:
  simulate: {command: [/bin/sh, -c, "mkdir -p {sequence}"]}
  estimate: {command: [/bin/sh, -c, "mkdir estimate"]}
  evaluate: {command: [/bin/sh, -c, "echo not json > metrics.json"]}
)");
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  RunnerOptions o;
  o.results = dir.file("results");
  o.evio_binary = "/bin/true";
  const auto outcomes = runCampaign(c, expandJobs(c), o);
  ASSERT_EQ(outcomes.size(), 1u);
  EXPECT_EQ(outcomes[0].status, "failed");
  EXPECT_NE(outcomes[0].cause.find("evaluate: "), std::string::npos) << outcomes[0].cause;
  EXPECT_NE(outcomes[0].cause.find("metrics.json:1"), std::string::npos) << outcomes[0].cause;
}

TEST(CampaignResults, CollectMergesJobsFromOtherResultFolders) {
  // Two "nodes" without a shared file system each run half of the jobs.
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), shellCampaign(dir));
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  const auto jobs = expandJobs(c);
  const std::vector<Job> first(jobs.begin(), jobs.begin() + 10), second(jobs.begin() + 10, jobs.end());
  RunnerOptions o;
  o.evio_binary = "/bin/true";
  o.results = dir.file("node1");
  runCampaign(c, first, o);
  o.results = dir.file("node2");
  runCampaign(c, second, o);
  const CollectReport partial = collectResults(c, jobs, dir.file("merged"), {dir.file("node1")});
  EXPECT_EQ(partial.merged, 10u);
  EXPECT_EQ(partial.missing.size(), jobs.size() - 10);
  const CollectReport all = collectResults(c, jobs, dir.file("merged"), {dir.file("node1"), dir.file("node2")});
  EXPECT_EQ(all.merged, jobs.size() - 10);
  EXPECT_TRUE(all.missing.empty());
  EXPECT_EQ(all.done, jobs.size());
  EXPECT_EQ(all.failed, 12u);  // method "broken"
  // The merged summary equals one from a single run of everything.
  o.results = dir.file("single");
  runCampaign(c, jobs, o);
  EXPECT_EQ(io::readFile(dir.file("merged/summary.csv")), summaryCsv(c, jobs, dir.file("single")));
}

TEST(CampaignRunner, RemovesStagingOfDeadProcessesOnly) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), shellCampaign(dir));
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  ::waitpid(child, nullptr, 0);  // now certainly dead
  const fs::path staging = fs::path(dir.file("results")) / "staging";
  const fs::path dead = staging / ("a.good.s1.x." + hostName() + "." + std::to_string(child) + ".0");
  const fs::path alive = staging / ("a.good.s1.x." + hostName() + "." + std::to_string(::getpid()) + ".0");
  const fs::path other = staging / ("a.good.s1.x.otherhost." + std::to_string(child) + ".0");
  const fs::path seq = fs::path(dir.file("results")) / "sequences" / "a.1234" /
                       ("seed-1.tmp." + hostName() + "." + std::to_string(child) + ".3");
  for (const auto& p : {dead, alive, other, seq}) fs::create_directories(p);
  EXPECT_EQ(removeStaleStaging(c, dir.file("results")), 2u);
  EXPECT_FALSE(fs::exists(dead));
  EXPECT_FALSE(fs::exists(seq));
  EXPECT_TRUE(fs::exists(alive));
  EXPECT_TRUE(fs::exists(other));  // another node's: not ours to judge
}

TEST(SlurmScript, GroupsJobsBySequenceIntoArrayTasks) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("c.yaml"), shellCampaign(dir) + "slurm: {jobs_per_task: 4, max_parallel: 2, time: \"00:05:00\"}\n");
  const Campaign c = loadCampaign(dir.file("c.yaml"));
  const auto jobs = expandJobs(c);
  SlurmPlanInputs in{"/opt/evio", "/results", "/results/slurm/tasks.txt", "/results/slurm", {"seeds=[1,2,3]"}};
  const SlurmPlan plan = slurmPlan(c, jobs, in);
  EXPECT_EQ(plan.tasks, 6u);  // 24 jobs, 4 per task
  EXPECT_NE(plan.script.find("#SBATCH --array=0-5%2\n"), std::string::npos);
  EXPECT_NE(plan.script.find("#SBATCH --time=00:05:00\n"), std::string::npos);
  EXPECT_NE(plan.script.find("'/opt/evio' campaign run-task"), std::string::npos);
  EXPECT_NE(plan.script.find("--set 'seeds=[1,2,3]'"), std::string::npos);
  EXPECT_NE(plan.script.find("--task \"${SLURM_ARRAY_TASK_ID}\""), std::string::npos);
  std::set<std::string> all;
  for (std::size_t t = 0; t < plan.tasks; ++t) {
    const auto ids = taskJobIds(plan.tasks_text, t, "tasks.txt");
    EXPECT_EQ(ids.size(), 4u);
    all.insert(ids.begin(), ids.end());
    // The 4 jobs sharing one sequence (2 methods × 2 sweep values) share a task.
    std::set<std::string> keys;
    for (const auto& id : ids)
      for (const auto& j : jobs)
        if (j.id == id) keys.insert(j.sequence_key);
    EXPECT_EQ(keys.size(), 1u);
  }
  EXPECT_EQ(all.size(), jobs.size());
  EXPECT_THROW(taskJobIds(plan.tasks_text, 6, "tasks.txt"), Error);
  EXPECT_EQ(shellQuote("it's"), "'it'\\''s'");
}

TEST(CampaignResults, CsvRoundTripsQuotedFields) {
  const std::vector<std::string> fields = {"plain", "with,comma", "with \"quote\"", "", "multi\nline"};
  std::string text = "a,b\n";
  for (std::size_t i = 0; i < fields.size(); ++i) {
    if (i > 0) text += ',';
    text += csvField(fields[i]);
  }
  text += '\n';
  const auto rows = parseCsv(text);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1], fields);
}

}  // namespace
}  // namespace evio::experiments

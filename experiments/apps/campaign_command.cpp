// `evio campaign <campaign.yaml> -o <results> [-j N]`: runs a campaign's jobs
// (scenarios × methods × sweeps × seeds) in a pool of worker processes,
// resumably; `--slurm <script>` writes a Slurm job-array script instead;
// `evio campaign run-task` is what an array task runs; `evio campaign
// collect` merges results from nodes and writes summary.csv.
#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "data_root.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/stopwatch.h"
#include "evio/experiments/campaign.h"
#include "evio/experiments/campaign_results.h"
#include "evio/experiments/campaign_runner.h"
#include "evio/experiments/slurm_script.h"
#include "progress_line.h"

namespace evio::apps {

namespace {

namespace fs = std::filesystem;

std::string selfBinary() { return fs::read_symlink("/proc/self/exe").string(); }

std::string absolutePath(const std::string& p) { return fs::absolute(p).lexically_normal().string(); }

/// One line per finished job: "[done/total, failed, ETA] id status time cause".
class OutcomePrinter {
 public:
  void operator()(const experiments::CampaignProgress& p) {
    if (!p.last) return;
    const std::size_t done = p.skipped + p.finished;
    const double elapsed = watch_.seconds();
    const std::size_t left = p.total - done;
    const double eta_s = p.finished > 0 ? elapsed / static_cast<double>(p.finished) * static_cast<double>(left) : 0.0;
    char eta[32];
    if (eta_s >= 3600) std::snprintf(eta, sizeof(eta), "%dh%02dm", int(eta_s / 3600), int(eta_s / 60) % 60);
    else if (eta_s >= 60) std::snprintf(eta, sizeof(eta), "%dm%02ds", int(eta_s / 60), int(eta_s) % 60);
    else std::snprintf(eta, sizeof(eta), "%.0fs", eta_s);
    std::printf("[%*zu/%zu, %zu failed, ETA %s] %-40s %-8s %6.1f s%s%s\n",
                static_cast<int>(std::to_string(p.total).size()), done, p.total, p.failed, eta, p.last->id.c_str(),
                p.last->status.c_str(), p.last->wall_s, p.last->cause.empty() ? "" : "  ", p.last->cause.c_str());
    std::fflush(stdout);
  }

 private:
  Stopwatch watch_;
};

}  // namespace

void addCampaignCommand(CLI::App& app) {
  struct Args {
    std::string campaign;
    std::string results;
    std::vector<std::string> overrides;
    int workers = 1;
    bool retry_failed = false;
    std::string slurm_script;
    bool quiet = false;
    // collect
    std::vector<std::string> from;
    bool require_complete = false;
    // run-task
    std::string tasks_file;
    int task = -1;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("campaign",
                                     "Run a campaign (scenarios x methods x sweeps x seeds) locally or as a Slurm array");
  cmd->add_option("campaign", args->campaign, "campaign YAML (experiments/campaigns/*.yaml)");
  cmd->add_option("-o,--output", args->results, "results folder");
  cmd->add_option("--set", args->overrides, "override a campaign key: seeds=[1,2], slurm.jobs_per_task=4");
  cmd->add_option("-j,--jobs", args->workers, "jobs run in parallel (1..1024)")->check(CLI::Range(1, 1024));
  cmd->add_flag("--retry-failed", args->retry_failed, "re-run jobs that finished with status failed");
  cmd->add_option("--slurm", args->slurm_script,
                  "write a Slurm job-array script (and <results>/slurm/tasks.txt) instead of running");
  cmd->add_flag("-q,--quiet", args->quiet, "print only the final line");
  cmd->require_subcommand(0, 1);

  CLI::App* collect = cmd->add_subcommand("collect", "Merge results (from nodes) and write <results>/summary.csv");
  collect->add_option("campaign", args->campaign, "campaign YAML")->required();
  collect->add_option("-o,--output", args->results, "results folder")->required();
  collect->add_option("--set", args->overrides, "the same overrides as the campaign run");
  collect->add_option("--from", args->from, "further results folders to merge from (e.g. one per node)");
  collect->add_flag("--require-complete", args->require_complete, "exit with an error when jobs are missing");

  CLI::App* task = cmd->add_subcommand("run-task", "Run the jobs of one Slurm array task (used by the --slurm script)");
  task->add_option("campaign", args->campaign, "campaign YAML")->required();
  task->add_option("-o,--output", args->results, "results folder")->required();
  task->add_option("--set", args->overrides, "the same overrides as the campaign run");
  task->add_option("--tasks-file", args->tasks_file, "tasks file written by --slurm")->required();
  task->add_option("--task", args->task, "array task index (SLURM_ARRAY_TASK_ID)")->required();

  collect->callback([args] {
    const auto campaign = experiments::loadCampaign(resolveDataPath(args->campaign), args->overrides);
    const auto jobs = experiments::expandJobs(campaign);
    const auto r = experiments::collectResults(campaign, jobs, args->results, args->from);
    std::printf("campaign %s: %zu of %zu jobs done (%zu failed, %zu merged), %zu missing; summary: %s\n",
                campaign.name.c_str(), r.done, r.jobs, r.failed, r.merged, r.missing.size(),
                (fs::path(args->results) / "summary.csv").string().c_str());
    for (std::size_t i = 0; i < r.missing.size() && i < 20; ++i) std::printf("  missing: %s\n", r.missing[i].c_str());
    if (args->require_complete && !r.missing.empty())
      throw Error("campaign collect: " + std::to_string(r.missing.size()) + " jobs missing");
  });

  task->callback([args] {
    const auto campaign = experiments::loadCampaign(resolveDataPath(args->campaign), args->overrides);
    const auto all = experiments::expandJobs(campaign);
    const auto ids = experiments::taskJobIds(io::readFile(args->tasks_file), static_cast<std::size_t>(args->task),
                                             args->tasks_file);
    std::vector<experiments::Job> jobs;
    for (const auto& id : ids) {
      const auto it = std::find_if(all.begin(), all.end(), [&](const auto& j) { return j.id == id; });
      if (it == all.end())
        throw Error(args->tasks_file + ": job " + id + " is not in the campaign (changed since --slurm?)");
      jobs.push_back(*it);
    }
    experiments::RunnerOptions options;
    options.results = absolutePath(args->results);
    options.evio_binary = selfBinary();
    const auto outcomes = experiments::runCampaign(campaign, jobs, options, OutcomePrinter());
    std::printf("task %d: %zu jobs\n", args->task, outcomes.size());
    for (const auto& o : outcomes)
      if (o.status == "failed") exitCode() = 3;  // a task with failed jobs did not do what was asked
  });

  cmd->callback([cmd, args] {
    if (cmd->got_subcommand("collect") || cmd->got_subcommand("run-task")) return;
    if (args->campaign.empty()) throw Error("campaign: give a campaign YAML (or: campaign collect | run-task)");
    if (args->results.empty()) throw Error("campaign: give a results folder with -o");
    const auto campaign = experiments::loadCampaign(resolveDataPath(args->campaign), args->overrides);
    const auto jobs = experiments::expandJobs(campaign);
    const std::string results = absolutePath(args->results);

    if (!args->slurm_script.empty()) {
      std::vector<experiments::Job> pending;
      for (const auto& j : jobs)
        if (!experiments::jobDone(results, j, args->retry_failed)) pending.push_back(j);
      experiments::SlurmPlanInputs in;
      in.evio_binary = selfBinary();
      in.results = results;
      in.log_folder = (fs::path(results) / "slurm").string();
      in.tasks_file = (fs::path(results) / "slurm" / "tasks.txt").string();
      in.campaign_overrides = args->overrides;
      fs::create_directories(in.log_folder);
      const auto plan = experiments::slurmPlan(campaign, pending, in);
      io::writeFileAtomic(in.tasks_file, plan.tasks_text);
      io::writeFileAtomic(args->slurm_script, plan.script);
      ::chmod(args->slurm_script.c_str(), 0755);
      std::printf("wrote %s: %zu jobs (%zu done already) in %zu array tasks; submit with: sbatch %s\n",
                  args->slurm_script.c_str(), pending.size(), jobs.size() - pending.size(), plan.tasks,
                  args->slurm_script.c_str());
      return;
    }

    experiments::RunnerOptions options;
    options.results = results;
    options.workers = args->workers;
    options.retry_failed = args->retry_failed;
    options.evio_binary = selfBinary();
    ProgressLine line("campaign " + campaign.name, " jobs", args->quiet);
    const bool quiet = args->quiet;
    OutcomePrinter printOutcome;
    const auto outcomes = experiments::runCampaign(
        campaign, jobs, options, [&line, &printOutcome, quiet](const experiments::CampaignProgress& p) {
          if (!p.last && !quiet)
            std::printf("campaign: %zu jobs, %zu done already, %zu to run\n", p.total, p.skipped,
                        p.total - p.skipped);
          if (!quiet && p.last) {
            line.finish();
            printOutcome(p);
          }
          const std::size_t to_run = p.total - p.skipped;
          line.update(to_run ? static_cast<double>(p.finished) / static_cast<double>(to_run) : 1.0,
                      static_cast<double>(p.finished));
        });
    line.finish();
    experiments::writeSummary(campaign, jobs, results);
    std::size_t ok = 0, diverged = 0, failed = 0, skipped = 0;
    for (const auto& o : outcomes) {
      if (o.status == "ok") ++ok;
      else if (o.status == "diverged") ++diverged;
      else if (o.status == "skipped") ++skipped;
      else ++failed;
    }
    std::printf("campaign %s: %zu jobs: %zu ok, %zu diverged, %zu failed, %zu done before; summary: %s\n",
                campaign.name.c_str(), outcomes.size(), ok, diverged, failed, skipped,
                (fs::path(results) / "summary.csv").string().c_str());
    // Exit 3 when any job of the campaign (this run or before) failed.
    for (const auto& j : jobs)
      if (!experiments::jobDone(results, j, /*retry_failed=*/true)) exitCode() = 3;
  });
}

}  // namespace evio::apps

#pragma once
/// @file campaign_runner.h
/// Runs campaign jobs (campaign.h) as child processes, resumably.
///
/// Results folder:
///   <results>/jobs/<job-id>/        a finished job, complete: metrics.json
///                                   (+ metrics_poses.csv, metrics_rtf.csv),
///                                   job.yaml (what ran, exit codes, times, host),
///                                   logs/{simulate,estimate,evaluate}.log, estimate/
///   <results>/staging/<job-id>.<host>.<pid>   a job in flight
///   <results>/sequences/<scenario>.<hash>/seed-<seed>/   the sequence cache
///                                   (unless the campaign sets `cache`)
///   <results>/summary.csv           one row per job (campaign_results.h)
/// A job runs in its staging folder, which is renamed onto jobs/<job-id>
/// only when it is complete, so a job is done iff jobs/<job-id>/metrics.json
/// exists, and a killed campaign loses only the jobs in flight; a re-run
/// skips done jobs and removes this host's stale staging folders. A job
/// whose step fails (non-zero exit, signal, time limit) is done too, with a
/// metrics.json saying {"status": "failed", "cause": …}, unless
/// retry_failed. Simulated sequences are cached by scenario, simulate
/// overrides and seed; they too appear by an atomic rename, so workers on
/// several nodes may race for one safely.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "evio/experiments/campaign.h"

namespace evio::experiments {

/// A step's command for one job: placeholders replaced from `vars` ({name}
/// → vars["name"]; unknown names stay as written) and the whole-argument
/// placeholders of campaign.h expanded ({simulate_set}, {estimate_set},
/// {evaluate_set}, {estimator_config}, {method_option}).
std::vector<std::string> expandCommand(const Campaign& c, const CampaignStep& step,
                                       const std::map<std::string, std::string>& vars, const Job& job);

struct RunnerOptions {
  std::string results;         ///< results folder (created)
  int workers = 1;             ///< parallel jobs
  bool retry_failed = false;   ///< re-run jobs that finished with status failed
  std::string evio_binary;     ///< {evio}; {bin} is its folder
};

/// What became of one job.
struct JobOutcome {
  std::string id;
  std::string status;   ///< ok | diverged | failed (from metrics.json) | skipped (already done)
  std::string cause;
  double wall_s = 0.0;
};

struct CampaignProgress {
  std::size_t total = 0;     ///< jobs in the campaign
  std::size_t skipped = 0;   ///< done before this run
  std::size_t finished = 0;  ///< finished in this run
  std::size_t failed = 0;    ///< of those, status failed
  std::size_t running = 0;
  const JobOutcome* last = nullptr;  ///< the job that just finished (null on start)
};

using ProgressCallback = std::function<void(const CampaignProgress&)>;

/// Folder of a finished job.
std::string jobFolder(const std::string& results, const Job& job);

/// True when jobs/<id>/metrics.json exists (and, with retry_failed, does
/// not say failed).
bool jobDone(const std::string& results, const Job& job, bool retry_failed = false);

/// The sequence folder a job reads (the recorded sequence, or its cache entry).
std::string sequenceFolder(const Campaign& campaign, const std::string& results, const Job& job);

/// Runs one job in this thread (simulating its sequence first if needed).
JobOutcome runJob(const Campaign& campaign, const Job& job, const RunnerOptions& options);

/// Runs every job that is not done with `options.workers` parallel workers;
/// calls `progress` (from worker threads, serialised) on start and after each
/// job. Returns the outcomes of the jobs run (and skipped) in job order.
std::vector<JobOutcome> runCampaign(const Campaign& campaign, const std::vector<Job>& jobs,
                                    const RunnerOptions& options, const ProgressCallback& progress = {});

/// Removes staging folders (jobs and sequences) left by dead processes of
/// this host. Returns how many were removed.
std::size_t removeStaleStaging(const Campaign& campaign, const std::string& results);

/// The host name used in staging folder names.
std::string hostName();

}  // namespace evio::experiments

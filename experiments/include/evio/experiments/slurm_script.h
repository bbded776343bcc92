#pragma once
/// @file slurm_script.h
/// `evio campaign --slurm`: a Slurm job-array script whose array tasks run
/// the same job runner as the local pool (`evio campaign run-task`), and the
/// task list it reads. Jobs are grouped so that jobs sharing a simulated
/// sequence run in the same task (sorted by sequence, then id), jobs_per_task
/// to a task. Only jobs not yet done are listed. Results land in the shared
/// results folder (or per node, merged later by `evio campaign collect`).
///
/// tasks file (<results>/slurm/tasks.txt): one line per array task,
///   <task-index> <job-id> <job-id> …

#include <string>
#include <vector>

#include "evio/experiments/campaign.h"

namespace evio::experiments {

struct SlurmPlan {
  std::string script;      ///< the sbatch script
  std::string tasks_text;  ///< the tasks file
  std::size_t tasks = 0;   ///< array size
};

struct SlurmPlanInputs {
  std::string evio_binary;   ///< absolute
  std::string results;       ///< absolute
  std::string tasks_file;    ///< absolute path the tasks file will have
  std::string log_folder;    ///< absolute: %A_%a.out logs
  std::vector<std::string> campaign_overrides;  ///< --set given to `evio campaign`, repeated for run-task
};

/// Plans an array over `pending` jobs (not empty). Throws evio::Error for no jobs.
SlurmPlan slurmPlan(const Campaign& campaign, const std::vector<Job>& pending, const SlurmPlanInputs& inputs);

/// The job ids of task `index` in a tasks file's text; throws when absent.
std::vector<std::string> taskJobIds(const std::string& tasks_text, std::size_t index, const std::string& name);

/// `text` as one single-quoted shell word.
std::string shellQuote(const std::string& text);

}  // namespace evio::experiments

#include "evio/experiments/slurm_script.h"

#include <algorithm>
#include <sstream>

#include "evio/core/error.h"

namespace evio::experiments {

std::string shellQuote(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

SlurmPlan slurmPlan(const Campaign& c, const std::vector<Job>& pending, const SlurmPlanInputs& in) {
  require(!pending.empty(), "campaign --slurm: every job is done already; nothing to submit");
  std::vector<const Job*> jobs;
  for (const auto& j : pending) jobs.push_back(&j);
  std::sort(jobs.begin(), jobs.end(), [](const Job* a, const Job* b) {
    return a->sequence_key != b->sequence_key ? a->sequence_key < b->sequence_key : a->id < b->id;
  });
  const auto per = static_cast<std::size_t>(c.slurm.jobs_per_task);
  SlurmPlan plan;
  plan.tasks = (jobs.size() + per - 1) / per;
  for (std::size_t t = 0; t < plan.tasks; ++t) {
    plan.tasks_text += std::to_string(t);
    for (std::size_t k = t * per; k < std::min(jobs.size(), (t + 1) * per); ++k) plan.tasks_text += " " + jobs[k]->id;
    plan.tasks_text += "\n";
  }
  std::string s = "#!/bin/bash\n";
  s += "#SBATCH --job-name=evio-" + c.name + "\n";
  s += "#SBATCH --array=0-" + std::to_string(plan.tasks - 1) +
       (c.slurm.max_parallel > 0 ? "%" + std::to_string(c.slurm.max_parallel) : "") + "\n";
  s += "#SBATCH --output=" + in.log_folder + "/%A_%a.out\n";
  s += "#SBATCH --cpus-per-task=" + std::to_string(c.slurm.cpus_per_task) + "\n";
  if (!c.slurm.time.empty()) s += "#SBATCH --time=" + c.slurm.time + "\n";
  if (!c.slurm.mem.empty()) s += "#SBATCH --mem=" + c.slurm.mem + "\n";
  if (!c.slurm.partition.empty()) s += "#SBATCH --partition=" + c.slurm.partition + "\n";
  for (const auto& e : c.slurm.extra) s += "#SBATCH " + e + "\n";
  s += "# Written by `evio campaign --slurm` for " + c.file + ":\n";
  s += "# " + std::to_string(jobs.size()) + " jobs in " + std::to_string(plan.tasks) + " array tasks (" +
       std::to_string(per) + " per task). Submit with: sbatch <this file>\n";
  s += "# Afterwards: evio campaign collect " + shellQuote(c.file) + " -o " + shellQuote(in.results) + "\n";
  s += "set -euo pipefail\n";
  s += "exec " + shellQuote(in.evio_binary) + " campaign run-task " + shellQuote(c.file);
  for (const auto& o : in.campaign_overrides) s += " --set " + shellQuote(o);
  s += " -o " + shellQuote(in.results) + " --tasks-file " + shellQuote(in.tasks_file) +
       " --task \"${SLURM_ARRAY_TASK_ID}\"\n";
  plan.script = s;
  return plan;
}

std::vector<std::string> taskJobIds(const std::string& tasks_text, std::size_t index, const std::string& name) {
  std::istringstream lines(tasks_text);
  std::string line;
  while (std::getline(lines, line)) {
    std::istringstream words(line);
    std::size_t t = 0;
    if (!(words >> t) || t != index) continue;
    std::vector<std::string> ids;
    for (std::string id; words >> id;) ids.push_back(id);
    return ids;
  }
  throw Error(name + ": no task " + std::to_string(index));
}

}  // namespace evio::experiments

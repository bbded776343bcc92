#pragma once
/// @file campaign_results.h
/// Aggregated campaign results and merging results from several nodes.
///
/// summary.csv: one row per job of the campaign, in job-id order, columns
///   job_id,scenario,method,sweep,seed,done,status,cause,<metric columns…>
/// where sweep is "key=value;…", done is 1 when the job has finished, and
/// the metric columns are the scalar leaves of the jobs' metrics.json as
/// dotted keys (paper.mpe_percent, ate.position_m.rmse, …) in order of first
/// appearance, without the input paths and the per-group alignment tags
/// (alignment.describe carries it once per row). It holds no times or hosts,
/// so the same finished jobs give a byte-identical file however they ran.

#include <string>
#include <vector>

#include "evio/experiments/campaign.h"

namespace evio::experiments {

/// summary.csv text for `jobs` from <results>/jobs/*/metrics.json.
std::string summaryCsv(const Campaign& campaign, const std::vector<Job>& jobs, const std::string& results);

struct CollectReport {
  std::size_t jobs = 0;
  std::size_t done = 0;
  std::size_t failed = 0;   ///< done with status failed
  std::size_t merged = 0;   ///< copied in from other folders
  std::vector<std::string> missing;  ///< ids of jobs not done anywhere
};

/// Merges finished jobs found in `from` result folders (e.g. one per node
/// without a shared file system) into `results` (each copied to a staging
/// folder and renamed into place), then writes <results>/summary.csv.
CollectReport collectResults(const Campaign& campaign, const std::vector<Job>& jobs, const std::string& results,
                             const std::vector<std::string>& from = {});

/// Writes <results>/summary.csv (atomically).
void writeSummary(const Campaign& campaign, const std::vector<Job>& jobs, const std::string& results);

/// Parses CSV text (RFC 4180 quoting) into rows of fields.
std::vector<std::vector<std::string>> parseCsv(const std::string& text);

}  // namespace evio::experiments

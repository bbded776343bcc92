#pragma once
/// @file campaign_report.h
/// `evio report`: campaign results (summary.csv, campaign_results.h) as
/// tables per scenario × method × sweep value: runs, success rate
/// (status ok), divergences and failures, and the Monte Carlo statistics of
/// the main metrics over the successful runs (median and quartiles of MPE,
/// median MYE, ATE RMSE, RPE, completion), the average NEES over the runs with
/// covariances with its two-sided 95 % χ² bounds, and the real-time factor.
/// Plots are drawn by experiments/plots/campaign_report.py from the same files.

#include <string>
#include <vector>

namespace evio::experiments {

/// Median and quartiles of a metric over a group's runs (NaN when none).
struct Spread {
  std::size_t count = 0;
  double median = 0.0;
  double q1 = 0.0;
  double q3 = 0.0;
};

/// Median and quartiles (linear interpolation between order statistics) of
/// the finite values.
Spread spreadOf(std::vector<double> values);

/// The estimator's self-diagnosis (status.yaml degraded or diverged) against
/// the ground truth's verdict (the divergence bound alone), over the runs
/// that did not fail and carry both.
struct SelfDiagnosisAgreement {
  std::size_t caught = 0;        ///< truth diverged, the estimator flagged it
  std::size_t missed = 0;        ///< truth diverged, the estimator said ok
  std::size_t false_alarms = 0;  ///< truth ok, the estimator flagged it
  std::size_t quiet = 0;         ///< truth ok, the estimator said ok

  std::size_t judged() const { return caught + missed + false_alarms + quiet; }
  /// Counts one run: estimator_status (ok, degraded, diverged) and truth_diverged ("true"/"false").
  void count(const std::string& estimator_status, const std::string& truth_diverged);
};

struct ReportGroup {
  std::string scenario, method, sweep;
  std::size_t runs = 0, ok = 0, diverged = 0, failed = 0, pending = 0;
  std::string alignment;   ///< alignment.describe of the first run (without the pose count)
  Spread mpe_percent;      ///< successful runs
  Spread mye_deg_per_m;
  Spread ate_position_m;   ///< ATE RMSE
  Spread ate_rotation_deg;
  Spread completion;       ///< all finished runs
  std::size_t nees_runs = 0;
  double anees = 0.0;      ///< mean over runs of their mean 6-dof NEES
  double anees_lower = 0.0, anees_upper = 0.0;  ///< 95 % bounds for nees_runs runs
  Spread rtf_median;       ///< of the runs' median RTF
  double rtf_max = 0.0;    ///< largest RTF interval of any run
  SelfDiagnosisAgreement self_diagnosis;

  double successRate() const { return runs ? static_cast<double>(ok) / static_cast<double>(runs) : 0.0; }
};

struct CampaignReport {
  std::size_t jobs = 0;
  std::size_t finished = 0;
  std::vector<ReportGroup> groups;  ///< in order of first appearance in summary.csv
};

/// Aggregates summary.csv rows (header first). Throws evio::Error when the
/// header lacks the fixed columns.
CampaignReport aggregateSummary(const std::vector<std::vector<std::string>>& rows);

/// The paper-style comparison (Markdown, "" unless the campaign has two or
/// more methods and no sweep): one row per scenario, one column per method
/// with the median MPE / MYE and successful / finished runs, and an average
/// row (mean over scenarios of the medians).
std::string comparisonMarkdown(const CampaignReport& report);

/// The self-diagnosis table (Markdown, "" when no run carries both verdicts).
std::string selfDiagnosisMarkdown(const CampaignReport& report);

/// The Markdown report: the comparison, a table per scenario, the
/// self-diagnosis against the truth, then `figures` (file names
/// relative to the report) and `notes` (e.g. plots skipped and why).
std::string reportMarkdown(const CampaignReport& report, const std::string& title,
                           const std::vector<std::string>& figures, const std::vector<std::string>& notes);

/// groups.csv: one row per group with every aggregate.
std::string reportCsv(const CampaignReport& report);

}  // namespace evio::experiments

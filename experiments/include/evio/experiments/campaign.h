#pragma once
/// @file campaign.h
/// A campaign: a matrix of scenarios × methods × parameter sweeps × seeds,
/// each cell an independent job whose steps are external `evio` commands
/// (simulate if needed, estimate, evaluate) run as child processes.
///
/// campaign.yaml (paths relative to the campaign file):
///
///   name: mars-hover                 # [A-Za-z0-9_-]; Slurm job name
///   seeds: [1, 2, 3]                 # or {first: 1, count: 50}
///   scenarios:                       # each: file (simulated) or sequence (recorded)
///     - name: hover
///       file: ../scenarios/hover.yaml
///       set: {duration_s: 30}        # optional overrides for the simulate step
///       estimate_set: {backend.slam_min_depth_m: 5}   # optional estimate overrides for this scenario
///       estimator_config: ../tuning/mars.yaml   # optional: this scenario's estimator configuration
///                                  # instead of the campaign's (another rig's parameter set)
///     - name: recorded
///       sequence: /data/boxes_6dof   # an existing sequence folder: no simulate
///   methods:
///     - name: eklt-vio
///       set: {estimator.n_e: 3200}   # optional overrides for the estimate step
///     - klt-vio                      # a bare name: no overrides
///   sweeps:                          # optional; every axis multiplies the matrix
///     - key: frontend.patch_size     # passed as --set key=value ...
///       step: estimate               # ... to this step: simulate | estimate (default) | evaluate
///       values: [17, 25]
///   evaluate: {alignment: {type: posyaw, window: time, start_s: 3, end_s: 8}}
///                                    # EvaluationOptions (trajectory_metrics.h), checked on load
///   cache: sequences                 # optional: simulated-sequence cache folder
///                                    # (default <results>/sequences)
///   steps:                           # optional: the commands (defaults below)
///     simulate: {command: [...], timeout_s: 0}   # 0: no time limit
///     estimate: {command: [...], timeout_s: 0}
///     evaluate: {command: [...], timeout_s: 0}
///   slurm: {time: "02:00:00", mem: "4G", partition: "", cpus_per_task: 2,
///           jobs_per_task: 1, max_parallel: 0, extra: ["--account=x"]}
///
/// Commands are argument lists, run without a shell, with the job's staging
/// folder as working directory. Placeholders ({name}, an unknown lower-case
/// name is an error; other braces are kept) inside arguments: {evio} (the
/// running evio binary), {bin} (its folder), {campaign_dir}, {scenario},
/// {scenario_file}, {method}, {seed}, {sequence} (the sequence folder being
/// simulated or read), {job} (the job's folder). An argument that is exactly
/// {simulate_set}, {estimate_set} or {evaluate_set} expands to the step's
/// overrides as "--set key=value" pairs (none when empty); {estimator_config}
/// to "--config <file>" when the scenario or else the campaign names one
/// (`estimator_config:`, relative to the campaign file), else nothing; {method_option} to
/// "--method <method name>" unless the job's estimator settings set `method`
/// themselves (a method named for its variant, e.g. `features15` with
/// `set: {method: eklt-vio, …}`), else nothing. Defaults:
///   simulate: {evio} simulate {scenario_file} -o {sequence} -q --set seed={seed} {simulate_set}
///   estimate: {evio} estimate {sequence} {estimator_config} {method_option} --init groundtruth -o estimate -q --set seed={seed}
///             {estimate_set}
///   evaluate: {evio} evaluate estimate {sequence} -o metrics.json -q {evaluate_set}
/// The estimate step must write the estimate folder (estimate_files.h) into
/// ./estimate; the evaluate step must write ./metrics.json.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace evio::experiments {

/// An ordered list of overrides key → value (value as YAML text).
using Overrides = std::vector<std::pair<std::string, std::string>>;

struct CampaignScenario {
  std::string name;
  std::string file;      ///< scenario file (absolute), for simulated scenarios
  std::string sequence;  ///< existing sequence folder (absolute), for recorded ones
  Overrides set;         ///< simulate overrides
  Overrides estimate_set;  ///< estimate overrides for this scenario (before the method's), e.g. the depth prior
  std::string estimator_config;  ///< absolute path of this scenario's estimator configuration, or empty (the campaign's)
};

struct CampaignMethod {
  std::string name;
  Overrides set;  ///< estimate overrides
};

struct SweepAxis {
  std::string key;
  std::string step = "estimate";  ///< simulate | estimate | evaluate
  std::vector<std::string> values;
};

struct CampaignStep {
  std::vector<std::string> command;
  double timeout_s = 0.0;  ///< 0: none
};

struct SlurmSettings {
  std::string time;       ///< --time, e.g. "02:00:00" (empty: cluster default)
  std::string mem;        ///< --mem, e.g. "4G"
  std::string partition;  ///< --partition
  int cpus_per_task = 1;
  int jobs_per_task = 1;  ///< campaign jobs run one after another by one array task
  int max_parallel = 0;   ///< --array=…%max_parallel (0: no limit)
  std::vector<std::string> extra;  ///< further "#SBATCH" options, e.g. "--account=x"
};

struct Campaign {
  std::string name;
  std::string file;  ///< absolute path of the campaign file
  std::string dir;   ///< its folder
  std::vector<std::uint64_t> seeds;
  std::vector<CampaignScenario> scenarios;
  std::vector<CampaignMethod> methods;
  std::vector<SweepAxis> sweeps;
  Overrides evaluate;  ///< flattened EvaluationOptions overrides
  std::string cache;   ///< absolute, or empty: <results>/sequences
  std::string estimator_config;  ///< absolute path of the estimator configuration, or empty (its defaults)
  CampaignStep simulate, estimate, evaluate_step;
  SlurmSettings slurm;
};

/// Loads and checks a campaign file; `overrides` ("seeds=[1,2]") are applied
/// to the YAML first. Throws evio::Error "file:line: key: message" for
/// unknown keys, wrong types, duplicate names, empty lists, bad evaluation
/// options or unknown placeholders.
Campaign loadCampaign(const std::string& path, const std::vector<std::string>& overrides = {});

/// One cell of the matrix.
struct Job {
  std::string id;         ///< "<scenario>.<method>.s<seed>.<hash8>": stable across runs and machines; the hash
                          ///< covers the scenario, method, seed, every override and the estimator config's file name
  std::size_t scenario = 0;  ///< index into Campaign::scenarios
  std::size_t method = 0;    ///< index into Campaign::methods
  std::uint64_t seed = 0;
  Overrides sweep;          ///< this cell's sweep values (key → value)
  Overrides simulate_set;   ///< scenario overrides + simulate sweeps
  Overrides estimate_set;   ///< method overrides + estimate sweeps
  Overrides evaluate_set;   ///< campaign evaluate options + evaluate sweeps
  std::string estimator_config;  ///< the scenario's estimator configuration, else the campaign's (absolute, or empty)
  std::string sequence_key; ///< cache path "<scenario>.<hash8>/seed-<seed>" ("" for recorded sequences)
};

/// The jobs of a campaign, seed outermost (a campaign stopped part-way holds
/// whole seeds: every cell has the same number of runs), then the variant
/// (method, sweep values), then the scenario innermost, so that with several
/// scenarios neighbouring jobs need different sequences and parallel workers
/// simulate different sequences at once. The id
/// hashes scenario, method, seed and every override, so a changed
/// configuration makes new jobs instead of reusing stale results.
std::vector<Job> expandJobs(const Campaign& campaign);

/// "key=value;key=value" of an override list ("" when empty).
std::string overridesText(const Overrides& overrides);

/// 64-bit FNV-1a of `text` (stable hash for ids).
std::uint64_t fnv1a64(const std::string& text);

}  // namespace evio::experiments

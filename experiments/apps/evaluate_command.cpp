// `evio evaluate <estimate> <groundtruth> [-o metrics.json|metrics.csv]`:
// scores an estimated trajectory against ground truth (docs/evaluation.md) and
// prints a table. With -o *.json it also writes <stem>_poses.csv (per-pose
// errors, NEES) and <stem>_rtf.csv (real-time factor series) beside it,
// before the JSON, so a metrics.json that exists is complete.
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/staged_folder.h"
#include "evio/experiments/estimate_files.h"
#include "evio/experiments/metrics_format.h"
#include "evio/experiments/trajectory_metrics.h"

namespace evio::apps {

void addEvaluateCommand(CLI::App& app) {
  struct Args {
    std::string estimate;
    std::string groundtruth;
    std::string output;
    std::string config;
    std::vector<std::string> overrides;
    std::string align;
    int first_n = 0;
    std::vector<double> window_s;
    bool paper = false;
    std::string covariance, timing, status;
    bool no_companions = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("evaluate", "Score an estimated trajectory against ground truth (ATE, RPE, MPE, NEES, RTF)");
  cmd->add_option("estimate", args->estimate,
                  "estimate: TUM trajectory, or an estimate folder (trajectory.txt, trajectory_covariance.txt, "
                  "timing.txt, status.yaml)")
      ->required();
  cmd->add_option("groundtruth", args->groundtruth, "ground truth: TUM file or a sequence folder")->required();
  cmd->add_option("-o,--output", args->output, "write metrics: .json (with _poses.csv, _rtf.csv) or .csv");
  cmd->add_option("--config", args->config, "evaluation options YAML (EvaluationOptions)");
  cmd->add_option("--set", args->overrides,
                  "override an option: alignment.type=se3, association.max_time_difference_s=0.01, "
                  "rpe.lengths_m=[1,5], divergence.offset_m=2");
  cmd->add_option("--align", args->align, "alignment type")->check(CLI::IsMember({"posyaw", "se3", "sim3", "none"}));
  cmd->add_option("--first", args->first_n, "align on the first N associated poses");
  cmd->add_option("--window", args->window_s, "align on t0+A .. t0+B s (t0: first ground-truth time)")
      ->expected(2);
  cmd->add_flag("--paper", args->paper, "the paper's protocol as campaigns score it: posyaw alignment on t0+3 .. t0+8 s; NEES, divergence and "
                "completion in the estimate's own frame (the filter started from ground truth)");
  cmd->add_option("--covariance", args->covariance, "pose covariances (TUM covariance variant) for NEES");
  cmd->add_option("--timing", args->timing, "timing.txt for the real-time factor");
  cmd->add_option("--status", args->status, "the estimator's status.yaml");
  cmd->add_flag("--no-companions", args->no_companions,
                "do not pick up trajectory_covariance.txt, timing.txt, status.yaml beside the estimate");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    config::Document doc = args->config.empty() ? config::loadString("{}", "<defaults>") : config::loadFile(args->config);
    for (const auto& o : args->overrides) config::applyOverride(doc, o);
    experiments::EvaluationOptions options;
    config::fill(doc, "", options);
    if (args->paper) {  // exactly as the shipped campaigns score (EvaluationOptions::paper)
      const experiments::EvaluationOptions paper = experiments::EvaluationOptions::paper();
      options.alignment = paper.alignment;
      options.nees.use_alignment = paper.nees.use_alignment;
      options.divergence.use_alignment = paper.divergence.use_alignment;
    }
    if (!args->align.empty()) options.alignment.type = args->align;
    if (args->first_n > 0) {
      options.alignment.window = "first";
      options.alignment.first_n = args->first_n;
    }
    if (!args->window_s.empty()) {
      options.alignment.window = "time";
      options.alignment.start_s = args->window_s[0];
      options.alignment.end_s = args->window_s[1];
    }
    options.validate();
    io::requireNotStaging(args->estimate);
    io::requireNotStaging(args->groundtruth);

    experiments::EstimateFiles files = experiments::findEstimateFiles(args->estimate);
    if (args->no_companions) files = {files.trajectory, "", "", ""};
    if (!args->covariance.empty()) files.covariance = args->covariance;
    if (!args->timing.empty()) files.timing = args->timing;
    if (!args->status.empty()) files.status = args->status;

    experiments::MetricsSources sources;
    sources.estimate = files.trajectory;
    sources.groundtruth = experiments::findGroundtruthFile(args->groundtruth);
    sources.covariance = files.covariance;
    sources.timing = files.timing;
    sources.status = files.status;

    experiments::EvaluationInputs in;
    in.estimate = io::readTum(sources.estimate);
    in.groundtruth = io::readTum(sources.groundtruth);
    if (!files.covariance.empty()) in.covariance = io::readTumCovariance(files.covariance);
    if (!files.timing.empty()) in.timing = io::readTimingText(files.timing);
    if (!files.status.empty()) in.status = io::readStatusYaml(files.status);
    const experiments::Metrics metrics = experiments::evaluateTrajectory(in, options);
    const experiments::JsonValue json = experiments::metricsJson(metrics, options, sources);

    if (!args->output.empty()) {
      const fs::path out(args->output);
      if (out.extension() != ".json" && out.extension() != ".csv")
        throw Error("--output: must end in .json or .csv (got '" + args->output + "')");
      // The metrics file and its companions are published together (core/io/staged_folder.h).
      io::StagedFiles staged(args->output);
      if (out.extension() == ".json") {
        const fs::path stem = out.parent_path() / out.stem();
        io::writeFileAtomic(staged.path(stem.string() + "_poses.csv"), experiments::poseErrorsCsv(metrics));
        if (metrics.rtf.available)
          io::writeFileAtomic(staged.path(stem.string() + "_rtf.csv"), experiments::rtfCsv(metrics));
        else
          staged.drop(stem.string() + "_rtf.csv");
        io::writeFileAtomic(staged.path(args->output), json.dump());
      } else {
        io::writeFileAtomic(staged.path(args->output), experiments::metricsCsv(json));
      }
      staged.publish();
    }
    if (!args->quiet) std::fputs(experiments::metricsTable(metrics).c_str(), stdout);
  });
}

}  // namespace evio::apps

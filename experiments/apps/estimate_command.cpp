// `evio estimate <sequence> --method eklt-vio|klt-vio|haste-vio|tracks [--config file]
//  [--init static|groundtruth] [--set key=value] [--tracks file] [--track-noise px] -o <folder>`: runs an
// estimator pipeline (estimator/pipeline/pipeline.h) over a sequence folder
// and writes the estimate folder (trajectory.txt, trajectory_covariance.txt,
// imu_state.txt, timing.txt, status.yaml, config.yaml, summary.yaml).
// Divergence is a status in status.yaml (exit code 0); status failed exits 3;
// bad input is an error (exit 1). The folder is staged and published whole.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/core/io/staged_folder.h"
#include "evio/estimator/pipeline/method_settings.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "data_root.h"
#include "progress_line.h"

namespace evio::apps {

void addEstimateCommand(CLI::App& app) {
  struct Args {
    std::string folder;
    std::string method;
    std::string config;
    std::vector<std::string> overrides;
    std::string tracks;
    double track_noise_px = -1.0;
    std::string init;
    std::string output;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("estimate", "Run EKLT-VIO, KLT-VIO or the backend on tracks over a sequence");
  cmd->add_option("sequence", args->folder, "sequence folder (Event-Camera Dataset layout)")->required();
  cmd->add_option("--method", args->method,
                  "eklt-vio, klt-vio, haste-vio or tracks (default: the `method` key of --config/--set)")
      ->check(CLI::IsMember({"eklt-vio", "klt-vio", "haste-vio", "tracks"}));
  cmd->add_option("--config", args->config,
                  "options YAML (estimator/config/*.yaml; keys: frontend, sync, backend, init, calibration, tracks, "
                  "output)");
  cmd->add_option("--set", args->overrides,
                  "override an option: sync.n_e=3200, backend.max_slam_features=15, "
                  "frontend.eklt.patch_size_px=17, init.mode=groundtruth (repeatable)");
  cmd->add_option("--tracks", args->tracks, "tracks file for --method tracks (default: <sequence>/truth/tracks.txt)");
  cmd->add_option("--track-noise", args->track_noise_px, "Gaussian noise added to the tracks, px (tracks.noise_px)");
  cmd->add_option("--init", args->init,
                  "initialisation: static (from the IMU; the default) or groundtruth (from groundtruth.txt: the "
                  "paper's protocol, what campaigns use); init.mode")
      ->check(CLI::IsMember({"static", "groundtruth"}));
  cmd->add_option("-o,--output", args->output, "estimate folder to write")->required();
  cmd->add_flag("-q,--quiet", args->quiet, "no progress line or summary");
  cmd->callback([args] {
    io::requireNotStaging(args->folder);
    config::Document doc =
        args->config.empty() ? config::loadString("{}", "<defaults>") : config::loadFile(resolveDataPath(args->config));
    for (const auto& o : args->overrides) config::applyOverride(doc, o);
    // --method wins; else the configuration's `method` (campaign methods set
    // it with --set, e.g. an eklt-vio variant on reconstructed frames).
    if (args->method.empty()) {
      const YAML::Node m = doc.root.IsMap() ? doc.root["method"] : YAML::Node();
      if (!m.IsDefined() || !m.IsScalar())
        throw Error("evio estimate: no method: give --method eklt-vio|klt-vio|haste-vio|tracks or method: in " +
                    (args->config.empty() ? std::string("--set") : args->config));
      args->method = config::scalarAs<std::string>(doc, m, "method");
      try {
        (void)estimator::PipelineOptions::forMethod(args->method);  // the one list of methods
      } catch (const Error& e) {
        throw Error(config::where(doc, m, "method") + ": " + e.what());
      }
    }
    config::applyOverride(doc, "method=" + args->method);
    estimator::applyMethodSettings(doc, args->method);  // the method's own section of the file (method_settings.h)
    if (!args->init.empty()) config::applyOverride(doc, "init.mode=" + args->init);
    if (!args->tracks.empty()) config::applyOverride(doc, "tracks.file=" + args->tracks);
    if (args->track_noise_px >= 0.0) config::applyOverride(doc, "tracks.noise_px=" + std::to_string(args->track_noise_px));
    estimator::PipelineOptions options = estimator::PipelineOptions::forMethod(args->method);
    config::fill(doc, "", options);

    io::StagedFolder out(args->output);  // published whole at the end, or not at all
    const bool event_method = args->method == "eklt-vio" || args->method == "haste-vio";  // progress in events
    ProgressLine line("estimate", event_method ? "ev" : "s data", args->quiet);
    const auto result = estimator::runPipeline(args->folder, options, out.path(), [&](const auto& p) {
      char label[96];
      std::snprintf(label, sizeof(label), "estimate %s t=%.2f s%s", args->method.c_str(), nsToSeconds(p.t_ns),
                    p.initialized ? "" : " (not initialised)");
      line.setLabel(label);
      line.update(p.fraction, event_method ? static_cast<double>(p.events) : nsToSeconds(p.t_ns));
    });
    line.finish();
    // "ok" with no pose at all (no events, never initialised) is no result.
    if (result.status.code == io::EstimateStatus::Code::kOk && result.counts.poses == 0)
      throw Error(args->folder + ": no pose was estimated (" + std::to_string(result.counts.events) + " events, " +
                  std::to_string(result.counts.frames) + " frames, " + std::to_string(result.counts.imu_samples) +
                  " IMU samples); nothing written to " + args->output);
    out.publish();
    // Divergence is an outcome (exit 0); a failed run did not do what was asked.
    if (result.status.code == io::EstimateStatus::Code::kFailed) exitCode() = 3;
    if (args->quiet) return;
    const double data_s =
        nsToSeconds(result.t_last_ns - result.initialization_t_ns.value_or(result.t_first_ns));
    std::printf("%s on %s: status %s%s%s\n", args->method.c_str(), args->folder.c_str(),
                std::string(io::estimateStatusName(result.status.code)).c_str(),
                result.status.cause.empty() ? "" : " — ", result.status.cause.c_str());
    std::printf("%llu poses; %llu events, %llu frames, %llu IMU samples, %llu measurement sets\n",
                static_cast<unsigned long long>(result.counts.poses),
                static_cast<unsigned long long>(result.counts.events),
                static_cast<unsigned long long>(result.counts.frames),
                static_cast<unsigned long long>(result.counts.imu_samples),
                static_cast<unsigned long long>(result.counts.measurement_sets));
    const auto& t = result.times;
    std::printf("wall %.2f s (CPU %.2f s) for %.2f s of data (overall RTF %.2f wall, %.2f CPU): read %.2f, "
                "frontend %.2f, backend %.2f, output %.2f, setup %.2f s wall\n",
                t.total_s, t.cpu_s, data_s, data_s > 0 ? t.total_s / data_s : 0.0, data_s > 0 ? t.cpu_s / data_s : 0.0,
                t.read_s, t.frontend_s, t.backend_s, t.output_s, t.setup_s);
    for (const auto& n : result.notes) std::printf("note: %s\n", n.c_str());
    std::printf("wrote %s\n", args->output.c_str());
  });
}

}  // namespace evio::apps

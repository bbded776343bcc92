// `evio track <sequence> --frontend eklt|klt|haste [--image-source frames|reconstructed]
//  [--config file] [--set key=value] [--noise] [--lag-compensated] -o tracks.txt`: runs a
// feature-tracking frontend over a sequence folder and writes its tracks
// (id t x y), with the resolved configuration beside them (<output>.yaml)
// and, with --noise, what the tracker stated with each point
// (<output>.noise.txt: id t quality cov_xx cov_xy cov_yy, px²); with
// --lag-compensated, the points as the filter is given them
// (<output>.lag_compensated.txt, id t x y).
#include <cstdio>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/staged_folder.h"
#include "evio/core/io/track_noise_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/experiments/track_sequence.h"
#include "progress_line.h"

namespace evio::apps {

void addTrackCommand(CLI::App& app) {
  struct Args {
    std::string folder;
    std::string frontend;
    std::string image_source;
    std::string config;
    std::vector<std::string> overrides;
    std::string output;
    bool noise = false;
    bool lag_compensated = false;
    double lag_velocity_window_s = 0.0;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("track", "Track features through a sequence (EKLT, KLT or HASTE frontend)");
  cmd->add_option("sequence", args->folder, "sequence folder")->required();
  cmd->add_option("--frontend", args->frontend, "eklt, klt or haste (overrides the config's tracker)")
      ->check(CLI::IsMember({"eklt", "klt", "haste"}));
  cmd->add_option("--image-source", args->image_source, "frames or reconstructed (from events)")
      ->check(CLI::IsMember({"frames", "reconstructed"}));
  cmd->add_option("--config", args->config, "frontend options YAML (estimator FrontendOptions at the root)");
  cmd->add_option("--set", args->overrides, "override an option: eklt.patch_size_px=17 (repeatable)");
  cmd->add_option("-o,--output", args->output, "tracks file to write (id t x y)")->required();
  cmd->add_flag("--noise", args->noise,
                "also write <output>.noise.txt: each point's quality and position covariance (id t quality cov_xx "
                "cov_xy cov_yy, px^2)");
  cmd->add_flag("--lag-compensated", args->lag_compensated,
                "also write <output>.lag_compensated.txt (id t x y): each point moved forward by the lag estimated "
                "online from the frames so far, as the filter is given it (EKLT, HASTE; EKLT's points measured on frames, its "
                "detections and bootstraps, are left as they are)");
  cmd->add_option("--lag-velocity-window", args->lag_velocity_window_s,
                  "with --lag-compensated: each track's velocity fitted over its points of this last span, s (the "
                  "synchroniser's velocity_window_s; 0: its newest two points)")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_flag("-q,--quiet", args->quiet, "no progress line or summary");
  cmd->callback([args] {
    io::requireNotStaging(args->folder);
    io::checkOutputFile(args->output);
    config::Document doc = args->config.empty() ? config::loadString("{}", "<defaults>") : config::loadFile(args->config);
    for (const auto& o : args->overrides) config::applyOverride(doc, o);
    if (!args->frontend.empty()) config::applyOverride(doc, "tracker=" + args->frontend);
    if (!args->image_source.empty()) config::applyOverride(doc, "image_source=" + args->image_source);
    estimator::FrontendOptions options;
    config::fill(doc, "", options);

    ProgressLine progress("tracking", "ev", args->quiet);
    const auto result = experiments::trackSequence(
        args->folder, options,
        [&](double fraction, std::uint64_t events) { progress.update(fraction, static_cast<double>(events)); },
        args->lag_compensated ? std::optional(experiments::LagCompensation{args->lag_velocity_window_s})
                              : std::nullopt);
    progress.finish();
    io::StagedFiles staged(args->output);  // the tracks and their .yaml published together
    io::writeTracksText(staged.path(args->output), result.samples,
                        {"evio track " + args->folder + " (" + options.tracker + ", " + options.image_source + ")",
                         "pixels of camera " + result.camera_name, "id t x y"});
    io::writeFileAtomic(staged.path(args->output + ".yaml"), config::toYaml(result.options));
    const std::string noise_file = args->output + ".noise.txt";
    if (args->noise) {
      io::writeTrackNoiseText(staged.path(noise_file), result.noise,
                              {"what the tracker stated with each point of " + args->output,
                               "quality in [0, 1]; covariance of the position, px^2 (0 0 0: not stated)",
                               "id t quality cov_xx cov_xy cov_yy"});
    } else {
      staged.drop(noise_file);  // an older run's noise would not belong to these tracks
    }
    const std::string compensated_file = args->output + ".lag_compensated.txt";
    if (args->lag_compensated) {
      io::writeTracksText(staged.path(compensated_file), result.compensated,
                          {"the points of " + args->output + " moved forward by the lag estimated online so far",
                           "(as the filter is given them; unmoved before the estimate exists)",
                           "pixels of camera " + result.camera_name, "id t x y"});
    } else {
      staged.drop(compensated_file);  // an older run's would not belong to these tracks
    }
    staged.publish();
    if (!args->quiet)
      std::printf("%llu tracks, %zu samples; %llu events (%llu after filters), %llu frames; %.2f s in the frontend "
                  "(%.0f events/s)\n",
                  static_cast<unsigned long long>(result.tracks), result.samples.size(),
                  static_cast<unsigned long long>(result.events), static_cast<unsigned long long>(result.events_kept),
                  static_cast<unsigned long long>(result.frames), result.processing_s,
                  result.processing_s > 0 ? static_cast<double>(result.events) / result.processing_s : 0.0);
  });
}

}  // namespace evio::apps

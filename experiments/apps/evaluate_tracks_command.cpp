// `evio evaluate-tracks <tracks.txt> <groundtruth> -o metrics.json|metrics.csv`:
// scores feature tracks against ground-truth tracks (a tracks.txt file, or a
// sequence folder holding truth/tracks.txt). JSON holds the summary and both
// tables; CSV writes error vs age to the file and the alive count to
// <stem>_alive.csv.
#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/experiments/track_metrics.h"

namespace evio::apps {

void addEvaluateTracksCommand(CLI::App& app) {
  struct Args {
    std::string tracks;
    std::string truth;
    std::string output;
    experiments::TrackMetricsOptions options;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("evaluate-tracks", "Score feature tracks against ground-truth tracks");
  cmd->add_option("tracks", args->tracks, "estimated tracks (id t x y)")->required();
  cmd->add_option("groundtruth", args->truth, "ground-truth tracks file, or a sequence folder with truth/tracks.txt")
      ->required();
  cmd->add_option("-o,--output", args->output, "metrics file: .json or .csv")->required();
  cmd->add_option("--match", args->options.match, "associate tracks by nearest start point or by id")
      ->check(CLI::IsMember({"nearest", "id"}));
  cmd->add_option("--radius", args->options.association_radius_px, "nearest: largest start distance, px");
  cmd->add_option("--max-error", args->options.max_error_px, "error that ends a track's scored life, px");
  cmd->add_option("--age-bin", args->options.age_bin_s, "bin width of error vs age, s");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    std::string truth_file = args->truth;
    if (fs::is_directory(truth_file)) truth_file = (fs::path(truth_file) / "truth" / "tracks.txt").string();
    const auto estimated = io::readTracksText(args->tracks);
    const auto truth = io::readTracksText(truth_file);
    const auto metrics = experiments::evaluateTracks(estimated, truth, args->options);
    const fs::path out(args->output);
    if (out.extension() == ".json") {
      io::writeFileAtomic(args->output, experiments::trackMetricsJson(metrics));
    } else if (out.extension() == ".csv") {
      io::writeFileAtomic(args->output, experiments::errorVsAgeCsv(metrics));
      io::writeFileAtomic((out.parent_path() / (out.stem().string() + "_alive.csv")).string(),
                          experiments::aliveCsv(metrics));
    } else {
      throw Error("--output: must end in .json or .csv (got '" + args->output + "')");
    }
    if (!args->quiet)
      std::printf("%llu of %llu tracks matched; mean error %.3f px (median %.3f); mean feature age %.3f s "
                  "(median %.3f)\n",
                  static_cast<unsigned long long>(metrics.matched_tracks),
                  static_cast<unsigned long long>(metrics.estimated_tracks), metrics.mean_error_px,
                  metrics.median_error_px, metrics.mean_feature_age_s, metrics.median_feature_age_s);
  });
}

}  // namespace evio::apps

// `evio evaluate-tracks <tracks.txt> <groundtruth> -o metrics.json|metrics.csv`:
// scores feature tracks against ground truth. Mode "depth" (the default for a
// sequence folder with truth/depth.txt) gives each estimated track its own
// truth from the depth map at its start and the ground-truth poses
// (experiments/depth_track_truth.h); mode "tracks" compares with ground-truth
// tracks (a tracks.txt file, or a sequence folder holding truth/tracks.txt).
// JSON holds the summary and both tables; CSV writes error vs age to the file
// and the alive count to <stem>_alive.csv.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/text_scanner.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/experiments/track_metrics.h"

namespace evio::apps {

namespace {

/// The camera named in a tracks file's header ("# pixels of camera NAME",
/// as `evio track` writes it), or "".
std::string trackCamera(const std::string& path) {
  io::LineReader lines(path);
  std::string_view line;
  const std::string_view key = "pixels of camera ";
  while (lines.next(line) && lines.lineNumber() <= 20) {
    if (line.empty() || line.front() != '#') break;
    const auto at = line.find(key);
    if (at == std::string_view::npos) continue;
    std::string name(line.substr(at + key.size()));
    while (!name.empty() && (name.back() == ' ' || name.back() == '\r')) name.pop_back();
    return name;
  }
  return "";
}

}  // namespace

void addEvaluateTracksCommand(CLI::App& app) {
  struct Args {
    std::string tracks;
    std::string truth;
    std::string output;
    experiments::TrackMetricsOptions options;
    experiments::DepthTruthOptions depth;
    std::string mode = "auto";
    std::string camera;
    std::string truth_output;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("evaluate-tracks", "Score feature tracks against ground-truth tracks");
  cmd->add_option("tracks", args->tracks, "estimated tracks (id t x y)")->required();
  cmd->add_option("groundtruth", args->truth,
                  "sequence folder (truth/depth.txt or truth/tracks.txt), or a ground-truth tracks file")
      ->required();
  cmd->add_option("--mode", args->mode,
                  "depth: truth of each track from depth maps and poses; tracks: against ground-truth tracks; "
                  "auto (default): depth when the folder has truth/depth.txt")
      ->check(CLI::IsMember({"auto", "depth", "tracks"}));
  cmd->add_option("--camera", args->camera,
                  "depth: camera of the track pixels (default: from the tracks file header, else the event camera)");
  cmd->add_option("--truth-output", args->truth_output,
                  "depth: also write each track's true positions (id t x y, until its truth ends)");
  cmd->add_option("--depth-time-tolerance", args->depth.max_depth_time_offset_s,
                  "depth: largest offset of a track's first sample from a depth-map stamp, s");
  cmd->add_option("--max-depth-curvature", args->depth.max_depth_curvature,
                  "depth: largest relative second difference of depth around a track's start");
  cmd->add_option("--occlusion-tolerance", args->depth.occlusion_tolerance,
                  "depth: relative depth excess that counts as occluded");
  cmd->add_option("-o,--output", args->output, "metrics file: .json or .csv")->required();
  cmd->add_option("--match", args->options.match, "associate tracks by nearest start point or by id")
      ->check(CLI::IsMember({"nearest", "id"}));
  cmd->add_option("--radius", args->options.association_radius_px, "nearest: largest start distance, px");
  cmd->add_option("--max-error", args->options.max_error_px, "error that ends a track's scored life, px");
  cmd->add_option("--age-bin", args->options.age_bin_s, "bin width of error vs age, s");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    const fs::path metrics_path(args->output);
    // Checked first: a bad name must not leave a --truth-output behind.
    if (metrics_path.extension() != ".json" && metrics_path.extension() != ".csv")
      throw Error("--output: must end in .json or .csv (got '" + args->output + "')");
    const bool folder = fs::is_directory(args->truth);
    std::string mode = args->mode;
    if (mode == "auto") mode = folder && fs::exists(fs::path(args->truth) / "truth" / "depth.txt") ? "depth" : "tracks";
    if (mode == "depth" && !folder) throw Error("--mode depth: needs a sequence folder (got '" + args->truth + "')");
    const auto estimated = io::readTracksText(args->tracks);
    experiments::TrackMetrics metrics;
    if (mode == "depth") {
      const std::string camera = args->camera.empty() ? trackCamera(args->tracks) : args->camera;
      const auto truth = experiments::loadDepthTrackTruth(args->truth, camera, args->depth);
      metrics = experiments::evaluateTracks(estimated, truth, args->options);
      if (!args->truth_output.empty()) {
        std::map<std::int64_t, std::vector<io::TrackSample>> by_id;
        for (const auto& s : estimated) by_id[s.id].push_back(s);
        std::vector<io::TrackSample> out;
        for (auto& [id, track] : by_id) {
          std::stable_sort(track.begin(), track.end(), [](const auto& a, const auto& b) { return a.t_ns < b.t_ns; });
          const auto tt = truth.truthOf(track);
          for (std::size_t k = 0; k < tt.uv.size(); ++k) out.push_back({id, track[k].t_ns, tt.uv[k]});
        }
        io::writeTracksText(args->truth_output, out,
                            {"evio evaluate-tracks: true positions of the tracks of " + args->tracks, "id t x y"});
      }
    } else {
      const std::string truth_file = folder ? (fs::path(args->truth) / "truth" / "tracks.txt").string() : args->truth;
      metrics = experiments::evaluateTracks(estimated, io::readTracksText(truth_file), args->options);
    }
    if (metrics_path.extension() == ".json") {
      io::writeFileAtomic(args->output, experiments::trackMetricsJson(metrics));
    } else {
      io::writeFileAtomic(args->output, experiments::errorVsAgeCsv(metrics));
      io::writeFileAtomic((metrics_path.parent_path() / (metrics_path.stem().string() + "_alive.csv")).string(),
                          experiments::aliveCsv(metrics));
    }
    if (!args->quiet)
      std::printf("%s: %llu of %llu tracks evaluable; mean error %.3f px (median %.3f); mean feature age %.3f s "
                  "(median %.3f)\n",
                  metrics.mode.c_str(), static_cast<unsigned long long>(metrics.matched_tracks),
                  static_cast<unsigned long long>(metrics.estimated_tracks), metrics.mean_error_px,
                  metrics.median_error_px, metrics.mean_feature_age_s, metrics.median_feature_age_s);
  });
}

}  // namespace evio::apps

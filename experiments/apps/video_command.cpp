// `evio video <sequence> -o seq.mp4`: frames beside accumulated events, with
// tracks, time and event rate on screen (experiments/sequence_video.h).
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "evio/experiments/sequence_video.h"
#include "progress_line.h"

namespace evio::apps {

void addVideoCommand(CLI::App& app) {
  struct Args {
    std::string folder;
    std::string output;
    experiments::VideoOptions options;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("video", "Write a sequence as a video: frames beside events, tracks, time, event rate");
  cmd->add_option("sequence", args->folder, "sequence folder")->required();
  cmd->add_option("-o,--output", args->output, "video file (.mp4 or .avi)")->required();
  cmd->add_option("--fps", args->options.fps, "video frames per second");
  cmd->add_option("--speed", args->options.speed, "sequence seconds per video second (0.25: 4x slow motion)");
  cmd->add_option("--window", args->options.window_s, "event accumulation window, s");
  cmd->add_option("--tracks", args->options.tracks,
                  "tracks file to overlay (default: <sequence>/truth/tracks.txt if present; 'none': no tracks)");
  cmd->add_option("--tail", args->options.track_tail_s, "drawn past of each track, s");
  cmd->add_option("--scale", args->options.scale, "video pixels per sensor pixel");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    ProgressLine line("video", "frames", args->quiet);
    const auto summary = experiments::writeSequenceVideo(args->folder, args->output, args->options,
                                                         [&line](double f) { line.update(f, f); });
    line.finish();
    if (args->quiet) return;
    std::printf("wrote %s: %zu frames of %dx%d (%s), %zu events drawn%s%s\n", args->output.c_str(), summary.frames,
                summary.width, summary.height, summary.codec.c_str(), summary.events,
                summary.tracks_file.empty() ? "" : ", tracks from ", summary.tracks_file.c_str());
  });
}

}  // namespace evio::apps

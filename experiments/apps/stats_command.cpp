// `evio stats <sequence> [--json] [-o stats.json] [--plot stats.png] [--set key=value] [-q]`:
// how much a sequence's events and frames look like a real DAVIS (issue 17).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/staged_folder.h"
#include "evio/experiments/sequence_stats.h"
#include "plot_runner.h"
#include "progress_line.h"

namespace evio::apps {

void addStatsCommand(CLI::App& app) {
  struct Args {
    std::string folder, output, plot;
    std::vector<std::string> overrides;
    bool json = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("stats", "Event and frame statistics of a sequence folder (real or simulated)");
  cmd->add_option("folder", args->folder, "sequence folder")->required();
  cmd->add_flag("--json", args->json, "print JSON instead of the table");
  cmd->add_option("-o,--output", args->output, "also write the JSON to this file");
  cmd->add_option("--plot", args->plot, "write a plot (PNG): event rate over time, brightness histogram");
  cmd->add_option("--set", args->overrides,
                  "override an option: burst_gap_s=0.005, isolation_window_s=0.01, rate_window_s=0.01, "
                  "width_px=240, height_px=180 (repeatable)");
  cmd->add_flag("-q,--quiet", args->quiet, "no progress line");
  cmd->callback([args] {
    config::Document doc = config::loadString("{}", "--set");
    for (const auto& o : args->overrides) config::applyOverride(doc, o);
    experiments::SequenceStatsOptions options;
    config::fill(doc, "", options);

    ProgressLine progress("measuring events", "ev", args->quiet);
    const auto stats = experiments::computeSequenceStats(args->folder, options, [&](double fraction, std::uint64_t n) {
      progress.update(fraction, static_cast<double>(n));
    });
    progress.finish();
    const std::string json = experiments::sequenceStatsJson(stats).dump();
    std::fputs(args->json ? json.c_str() : experiments::formatSequenceStats(stats).c_str(), stdout);
    if (!args->output.empty()) io::writeFileAtomic(args->output, json);
    if (!args->plot.empty()) {
      // The plot script reads the JSON: the -o file, else a temporary one.
      std::string input = args->output;
      io::InterruptCleanup remove_on_signal;  // the temporary JSON, also on SIGINT/SIGTERM
      if (input.empty()) {
        input = (std::filesystem::temp_directory_path() / ("evio_stats_" + std::to_string(::getpid()) + ".json")).string();
        remove_on_signal = io::InterruptCleanup(input);
        io::writeFileAtomic(input, json);
        remove_on_signal.confirmCreated();
      }
      const std::string problem = runPlotScript("stats.py", {input, args->plot});
      if (args->output.empty()) std::filesystem::remove(input);
      if (!problem.empty()) std::fprintf(stderr, "evio: warning: %s\n", problem.c_str());
    }
  });
}

}  // namespace evio::apps

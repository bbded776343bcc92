// `evio simulate <scenario.yaml> -o <folder>`: a complete sequence folder
// (events, frames, IMU, ground truth) from a scenario (simulator/scenario.h).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/io/staged_folder.h"
#include "evio/simulator/sequence_simulator.h"
#include "data_root.h"
#include "progress_line.h"

namespace evio::apps {

void addSimulateCommand(CLI::App& app) {
  struct Args {
    std::string scenario;
    std::string folder;
    std::vector<std::string> overrides;
    int threads = -1;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Simulate a scenario into a sequence folder (events, frames, IMU, ground truth)");
  cmd->add_option("scenario", args->scenario, "scenario YAML (experiments/scenarios/*.yaml)")->required();
  cmd->add_option("-o,--output", args->folder, "output folder")->required();
  cmd->add_option("--set", args->overrides,
                  "override a key: duration_s=2, seed=3, rig.imu.update_rate_hz=200, "
                  "trajectory.center_m=[0,0,2], output.write_events_txt=false");
  cmd->add_option("--threads", args->threads, "threads (0: all cores; the output does not depend on it)");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success (no progress line)");
  cmd->callback([args] {
    std::vector<std::string> overrides = args->overrides;
    if (args->threads >= 0) overrides.push_back("threads=" + std::to_string(args->threads));
    const simulator::Scenario scenario = simulator::loadScenario(resolveDataPath(args->scenario), overrides, dataRoot().string());
    io::StagedFolder out(args->folder);  // published whole at the end, or not at all
    ProgressLine line("simulate", "ev", args->quiet);
    const auto stats = simulator::simulateSequence(
        scenario, out.path(), [&line](const simulator::SimulationProgress& p) {
          char label[96];
          std::snprintf(label, sizeof(label), "simulate %.2f/%.2f s sim, %llu renders, %llu tiles", p.simulated_s,
                        p.total_s, static_cast<unsigned long long>(p.renders),
                        static_cast<unsigned long long>(p.tiles_rendered));
          line.setLabel(label);
          line.update(p.total_s > 0 ? p.simulated_s / p.total_s : 1.0, static_cast<double>(p.events));
        });
    out.publish();
    line.finish();
    if (args->quiet) return;
    std::printf("simulated %.3f s in %.1f s wall (%.3f x real time; scene build %.1f s)\n", stats.simulated_s,
                stats.wall_s, stats.realTimeFactor(), stats.scene_build_s);
    const double equivalents =
        stats.tile_count > 0 ? static_cast<double>(stats.tiles_rendered) / static_cast<double>(stats.tile_count) : 0.0;
    std::printf("schedule %s: %llu whole renders, %llu tile steps, %llu tiles traced (%.1f renders' worth, %.1f /s "
                "of render time)\n",
                stats.schedule.c_str(), static_cast<unsigned long long>(stats.renders),
                static_cast<unsigned long long>(stats.tile_steps), static_cast<unsigned long long>(stats.tiles_rendered),
                equivalents, stats.render_s > 0 ? equivalents / stats.render_s : 0.0);
    std::printf("%llu pixel updates (%.0f M/s in the event camera), %llu events (%.0f /s simulated), %llu frames\n",
                static_cast<unsigned long long>(stats.pixel_updates),
                stats.event_s > 0 ? static_cast<double>(stats.pixel_updates) / stats.event_s / 1e6 : 0.0,
                static_cast<unsigned long long>(stats.events),
                stats.simulated_s > 0 ? static_cast<double>(stats.events) / stats.simulated_s : 0.0,
                static_cast<unsigned long long>(stats.frames));
    std::printf("wrote %zu files to %s (figures: simulation_stats.yaml)\n", stats.files.size(), args->folder.c_str());
  });
}

}  // namespace evio::apps

// `evio trajectory <preset.yaml> -o <folder>`: ground truth, IMU and the true
// IMU state of a trajectory preset, plus a plot (trajectory.png).
#include <cstdio>
#include <string>
#include <vector>

#include "commands.h"
#include "data_root.h"
#include "evio/core/io/staged_folder.h"
#include "evio/simulator/trajectory_export.h"
#include "plot_runner.h"

namespace evio::apps {

void addTrajectoryCommand(CLI::App& app) {
  struct Args {
    std::string preset;
    std::string folder;
    std::vector<std::string> overrides;
    bool no_plot = false;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand(
      "trajectory", "Write groundtruth.txt, imu.txt and truth/imu_state.txt of a trajectory preset");
  cmd->add_option("preset", args->preset, "trajectory preset YAML (trajectories/presets/*.yaml)")->required();
  cmd->add_option("-o,--output", args->folder, "output folder")->required();
  cmd->add_option("--set", args->overrides,
                  "override a key: seed=3, duration_s=20, imu.update_rate_hz=1000, export.groundtruth_rate_hz=100");
  cmd->add_flag("--no-plot", args->no_plot, "do not draw trajectory.png");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    io::StagedFolder out(args->folder);  // published whole, or not at all
    const auto summary = exportTrajectoryPreset(resolveDataPath(args->preset), out.path(), args->overrides);
    out.publish();
    if (!args->quiet)
      std::printf("wrote %lld poses and %lld IMU samples to %s\n", static_cast<long long>(summary.groundtruth_poses),
                  static_cast<long long>(summary.imu_samples), args->folder.c_str());
    if (!args->no_plot) {
      const std::string problem = runPlotScript("plot_trajectory.py", {args->folder});
      if (!problem.empty()) std::fprintf(stderr, "evio: warning: %s\n", problem.c_str());
      else if (!args->quiet) std::printf("plot: %s/trajectory.png\n", args->folder.c_str());
    }
  });
}

}  // namespace evio::apps

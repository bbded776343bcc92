// `evio export <sequence> --format euroc -o <folder>`: a sequence in the
// EuRoC/ASL layout with Kalibr camchain and IMU yaml (euroc_export.h), for
// frame-based peers such as OpenVINS.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.h"
#include "evio/core/io/staged_folder.h"
#include "evio/experiments/euroc_export.h"

namespace evio::apps {

void addExportCommand(CLI::App& app) {
  struct Args {
    std::string sequence;
    std::string format = "euroc";
    std::string folder;
    experiments::EurocExportOptions options;
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("export", "Export a sequence for other tools (EuRoC/ASL layout + Kalibr yaml)");
  cmd->add_option("sequence", args->sequence, "sequence folder (sensors.yaml, images.txt, imu.txt, groundtruth.txt)")
      ->required();
  cmd->add_option("--format", args->format, "output format")->check(CLI::IsMember({"euroc"}));
  cmd->add_option("-o,--output", args->folder, "output folder")->required();
  cmd->add_option("--camera", args->options.camera, "camera of sensors.yaml exported as cam0 (default: the first frame camera)");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success (warnings still go to stderr)");
  cmd->callback([args] {
    io::requireNotStaging(args->sequence);
    io::StagedFolder out(args->folder);  // published whole, or not at all
    const auto s = experiments::exportEuroc(args->sequence, out.path(), args->options);
    out.publish();
    for (const auto& w : s.warnings) std::fprintf(stderr, "evio: warning: %s\n", w.c_str());
    if (!args->quiet)
      std::printf("exported %zu frames, %zu IMU samples, %zu ground-truth poses to %s (EuRoC layout, camchain.yaml, "
                  "imu.yaml)\n",
                  s.frames, s.imu_samples, s.groundtruth_poses, args->folder.c_str());
  });
}

}  // namespace evio::apps

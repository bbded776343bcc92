// `evio export <sequence> --format euroc -o <folder>`: a sequence in the
// EuRoC/ASL layout with Kalibr camchain and IMU yaml (euroc_export.h), for
// frame-based peers such as OpenVINS.
// `evio export <sequence> --format rosbag -o <file.bag>`: a ROS 1 bag
// (bags/include/evio/bags/bag_export.h), written under a temporary name and
// renamed when complete.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/bags/bag_export.h"
#include "evio/core/io/staged_folder.h"
#include "evio/experiments/euroc_export.h"

namespace evio::apps {

namespace {

struct ExportArgs {
  std::string sequence;
  std::string format = "euroc";
  std::string output;
  experiments::EurocExportOptions euroc;
  bags::BagExportOptions bag;
  std::vector<std::string> topics;
  bool quiet = false;
};

void exportEuroc(const ExportArgs& args) {
  io::StagedFolder out(args.output);  // published whole, or not at all
  const auto s = experiments::exportEuroc(args.sequence, out.path(), args.euroc);
  out.publish();
  for (const auto& w : s.warnings) std::fprintf(stderr, "evio: warning: %s\n", w.c_str());
  if (!args.quiet)
    std::printf("exported %zu frames, %zu IMU samples, %zu ground-truth poses to %s (EuRoC layout, camchain.yaml, "
                "imu.yaml)\n",
                s.frames, s.imu_samples, s.groundtruth_poses, args.output.c_str());
}

void exportRosbag(ExportArgs args) {
  args.bag.topics = bags::parseTopicOverrides(args.topics);
  const auto s = bags::exportBag(args.sequence, args.output, args.bag);
  if (!args.quiet)
    std::printf("exported %llu events (%llu messages), %llu frames, %llu IMU samples, %llu ground-truth poses%s%s to "
                "%s (ROS 1 bag, compression %s, sensor %d x %d)\n",
                static_cast<unsigned long long>(s.events), static_cast<unsigned long long>(s.event_messages),
                static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.imu_samples),
                static_cast<unsigned long long>(s.groundtruth_poses), s.camera_info ? ", camera info" : "",
                s.sensors_yaml ? ", sensors.yaml" : "", args.output.c_str(), args.bag.compression.c_str(), s.width,
                s.height);
}

}  // namespace

void addExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export", "Export a sequence for other tools (EuRoC/ASL layout + Kalibr yaml, or a ROS 1 bag)");
  cmd->add_option("sequence", args->sequence, "sequence folder (sensors.yaml, images.txt, imu.txt, groundtruth.txt)")
      ->required();
  cmd->add_option("--format", args->format, "output format: euroc (a folder) or rosbag (a .bag file)")
      ->check(CLI::IsMember({"euroc", "rosbag"}));
  cmd->add_option("-o,--output", args->output, "output folder (euroc) or bag file (rosbag)")->required();
  cmd->add_option("--camera", args->euroc.camera,
                  "euroc: camera of sensors.yaml exported as cam0 (default: the first frame camera)");
  cmd->add_option("--compression", args->bag.compression, "rosbag: chunk compression none, bz2 or lz4")
      ->check(CLI::IsMember({"none", "bz2", "lz4"}));
  cmd->add_option("--event-window", args->bag.event_window_s, "rosbag: time span of one EventArray message, s [1e-6, 1]");
  cmd->add_option("--max-events-per-message", args->bag.max_events_per_message,
                  "rosbag: most events in one EventArray message [1, 1e7]");
  cmd->add_option("--topic", args->topics,
                  "rosbag: kind=/name renames a kind's topic (events, frames, imu, groundtruth, camera_info, "
                  "sensors); kind= leaves it out");
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success (warnings still go to stderr)");
  cmd->callback([args] {
    io::requireNotStaging(args->sequence);
    if (args->format == "rosbag") exportRosbag(*args);
    else exportEuroc(*args);
  });
}

}  // namespace evio::apps

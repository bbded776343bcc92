// `evio import <bag> -o <folder>`: a ROS 1 bag into a sequence folder
// (bags/include/evio/bags/bag_import.h), published whole or not at all.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/bags/bag_import.h"
#include "evio/core/io/staged_folder.h"

namespace evio::apps {

namespace {

std::string summaryLine(const bags::BagImportSummary& s, const std::string& folder) {
  std::string topics;
  for (const auto& [kind, name] : s.topics)
    topics += (topics.empty() ? "" : ", ") + std::string(bags::topicKindName(kind)) + "=" + name;
  char line[512];
  std::snprintf(line, sizeof(line),
                "imported %llu events (%llu messages), %llu frames, %llu IMU samples, %llu ground-truth poses, "
                "%llu camera infos to %s (%s)",
                static_cast<unsigned long long>(s.events), static_cast<unsigned long long>(s.event_messages),
                static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(s.imu_samples),
                static_cast<unsigned long long>(s.groundtruth_poses), static_cast<unsigned long long>(s.camera_infos),
                folder.c_str(), topics.c_str());
  return line;
}

}  // namespace

void addImportCommand(CLI::App& app) {
  struct Args {
    std::string bag;
    std::string folder;
    std::vector<std::string> topics;
    std::string events_format = "txt";
    bool quiet = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("import", "Import a ROS 1 bag (events, frames, IMU, ground truth, camera info) as a sequence folder");
  cmd->add_option("bag", args->bag, "ROS 1 bag (uncompressed, bz2 or lz4)")->required();
  cmd->add_option("-o,--output", args->folder, "output sequence folder")->required();
  cmd->add_option("--topic", args->topics,
                  "kind=/name: read this topic for a kind (events, frames, imu, groundtruth, camera_info, sensors); "
                  "kind= skips it. Default: the bag's only topic of the kind's type");
  cmd->add_option("--events", args->events_format,
                  "events file: txt (events.txt, exact ns), h5 (events.h5, µs, with the sensor size) or both")
      ->check(CLI::IsMember({"txt", "h5", "both"}));
  cmd->add_flag("-q,--quiet", args->quiet, "print nothing on success");
  cmd->callback([args] {
    bags::BagImportOptions options;
    options.topics = bags::parseTopicOverrides(args->topics);
    options.events_format = args->events_format;
    io::requireNotStaging(args->bag);
    io::StagedFolder out(args->folder);  // published whole, or not at all
    const auto summary = bags::importBag(args->bag, out.path(), options);
    out.publish();
    if (!args->quiet) std::printf("%s\n", summaryLine(summary, args->folder).c_str());
  });
}

}  // namespace evio::apps

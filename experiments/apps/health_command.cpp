// `evio health <estimate folder> [--set health.key=value] [--json]`: judges an
// estimate's health.txt again with the estimator's self-diagnosis
// (estimator/pipeline/health_monitor.h), with the options the run used
// (its config.yaml) and any overrides: to see what other thresholds would
// have said without running the estimator again.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/core/io/health_txt.h"
#include "evio/estimator/pipeline/health_monitor.h"

namespace evio::apps {

void addHealthCommand(CLI::App& app) {
  struct Args {
    std::string folder;
    std::vector<std::string> overrides;
    bool json = false;
  };
  auto args = std::make_shared<Args>();
  CLI::App* cmd = app.add_subcommand("health", "Judge an estimate's health.txt with the self-diagnosis");
  cmd->add_option("estimate", args->folder, "estimate folder (health.txt, config.yaml)")->required();
  cmd->add_option("--set", args->overrides, "override a health option: health.nis_degraded_ratio=10 (repeatable)");
  cmd->add_flag("--json", args->json, "print the verdict as JSON");
  cmd->callback([args] {
    namespace fs = std::filesystem;
    const fs::path folder(args->folder);
    if (!fs::is_directory(folder)) throw Error(args->folder + ": not an estimate folder");
    const fs::path config = folder / "config.yaml";
    config::Document doc = fs::is_regular_file(config) ? config::loadFile(config.string())
                                                        : config::loadString("{}", "<defaults>");
    for (const auto& o : args->overrides) config::applyOverride(doc, o);
    estimator::HealthOptions options;
    if (doc.root.IsMap() && doc.root["health"].IsDefined()) config::fill(doc, "health", options);
    estimator::HealthMonitor monitor(options);
    const std::vector<io::HealthRow> rows = io::readHealthText((folder / "health.txt").string());
    for (const io::HealthRow& r : rows) monitor.observe(r);
    const estimator::HealthVerdict& v = monitor.verdict();
    const std::string status(io::estimateStatusName(v.code));
    const double t_s = nsToSeconds(v.t_ns);
    if (args->json) {
      std::printf("{\"health\": \"%s\", \"time_s\": %s, \"updates\": %zu}\n", status.c_str(),
                  v.code == io::EstimateStatus::Code::kOk ? "null" : std::to_string(t_s).c_str(), rows.size());
      return;
    }
    if (v.code == io::EstimateStatus::Code::kOk)
      std::printf("health: ok over %zu updates\n", rows.size());
    else
      std::printf("health: %s at %.3f s: %s\n", status.c_str(), t_s, v.cause.c_str());
  });
}

}  // namespace evio::apps

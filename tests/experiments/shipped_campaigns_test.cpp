// Every shipped campaign (experiments/campaigns/*.yaml) resolves, job by job,
// to a scenario the simulator accepts and to estimator settings the
// estimator accepts — checked here in milliseconds rather than by a job
// failing hours into a campaign (as mars_flight's 30 s did against the
// flight preset's 45 s of phases).

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "evio/experiments/campaign.h"
#include "evio/simulator/scenario.h"

namespace evio::experiments {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> asArguments(const Overrides& overrides) {
  std::vector<std::string> out;
  for (const auto& [key, value] : overrides) out.push_back(key + "=" + value);
  return out;
}

/// The value after "--config" in the estimate command, or "" (the defaults).
std::string estimatorConfig(const Campaign& c) {
  const auto& cmd = c.estimate.command;
  const auto it = std::find(cmd.begin(), cmd.end(), "--config");
  return it != cmd.end() && it + 1 != cmd.end() ? *(it + 1) : std::string();
}

/// What `evio estimate --config <config> --set …` does with the settings
/// (estimate_command.cpp): the method from the settings, then every key filled.
void checkEstimatorSettings(const std::string& config_file, const Overrides& estimate_set, const std::string& method) {
  config::Document doc = config_file.empty() ? config::loadString("{}", "<defaults>") : config::loadFile(config_file);
  for (const auto& o : asArguments(estimate_set)) config::applyOverride(doc, o);
  std::string m = method;
  if (const YAML::Node node = doc.root["method"]; node.IsDefined()) m = node.as<std::string>();
  config::applyOverride(doc, "method=" + m);
  estimator::PipelineOptions options = estimator::PipelineOptions::forMethod(m);
  config::fill(doc, "", options);
}

TEST(ShippedCampaigns, EveryJobHasAValidScenarioAndEstimatorSettings) {
  const fs::path root = EVIO_SOURCE_DIR;
  int campaigns = 0;
  for (const auto& entry : fs::directory_iterator(root / "experiments" / "campaigns")) {
    if (entry.path().extension() != ".yaml" || entry.path().stem() == "smoke") continue;  // smoke: a fake estimator
    ++campaigns;
    SCOPED_TRACE(entry.path().string());
    const Campaign c = loadCampaign(entry.path().string());
    std::string config = estimatorConfig(c);
    if (!config.empty() && fs::path(config).is_relative()) config = (root / config).string();  // run from the repository
    std::set<std::string> scenarios_seen, settings_seen;
    for (const Job& job : expandJobs(c)) {
      const CampaignScenario& sc = c.scenarios[job.scenario];
      if (!sc.file.empty() && scenarios_seen.insert(sc.file + "|" + overridesText(job.simulate_set)).second) {
        SCOPED_TRACE(job.id);
        try {
          (void)simulator::loadScenario(sc.file, asArguments(job.simulate_set), root.string());
        } catch (const Error& e) {
          ADD_FAILURE() << job.id << ": " << e.what();
        }
      }
      if (settings_seen.insert(overridesText(job.estimate_set)).second) {
        try {
          checkEstimatorSettings(config, job.estimate_set, c.methods[job.method].name);
        } catch (const Error& e) {
          ADD_FAILURE() << job.id << ": " << e.what();
        }
      }
    }
  }
  EXPECT_GE(campaigns, 6);  // main, paper_table, rotation_only, mars, update_rate, speedup
}

}  // namespace
}  // namespace evio::experiments

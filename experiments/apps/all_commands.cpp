#include "commands.h"

namespace evio::apps {

void addAllCommands(CLI::App& app) {
  addInfoCommand(app);
  addStatsCommand(app);
  addTrajectoryCommand(app);
  addRenderCommand(app);
  addTrackCommand(app);
  addEvaluateTracksCommand(app);
  addEvaluateCommand(app);
  addCampaignCommand(app);
  addReportCommand(app);
  addExportCommand(app);
  addImportCommand(app);
  addSimulateCommand(app);
  addEstimateCommand(app);
  addHealthCommand(app);
  addVideoCommand(app);
}

}  // namespace evio::apps

// The `evio` command-line tool: one executable, one subcommand per job.
// Errors are printed as one line on stderr with a non-zero exit code.
#include <cstdio>
#include <exception>

#include "commands.h"
#include "evio/core/error.h"
#include "evio/core/version.h"

int main(int argc, char** argv) {
  CLI::App app{"evio: event-camera visual-inertial odometry test bench (simulate, estimate, evaluate)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", evio::evioVersion());
  evio::apps::addInfoCommand(app);
  evio::apps::addStatsCommand(app);
  evio::apps::addTrajectoryCommand(app);
  evio::apps::addRenderCommand(app);
  evio::apps::addTrackCommand(app);
  evio::apps::addEvaluateTracksCommand(app);
  evio::apps::addEvaluateCommand(app);
  evio::apps::addCampaignCommand(app);
  evio::apps::addReportCommand(app);
  evio::apps::addExportCommand(app);
  evio::apps::addSimulateCommand(app);
  evio::apps::addEstimateCommand(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const evio::Error& e) {
    std::fprintf(stderr, "evio: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "evio: internal error: %s\n", e.what());
    return 2;
  }
  return 0;
}

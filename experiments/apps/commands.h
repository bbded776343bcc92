#pragma once
/// @file commands.h
/// Each `evio` subcommand lives in its own <name>_command.cpp and registers
/// itself on the top-level CLI11 app through one of these functions.

#include <CLI/CLI.hpp>

namespace evio::apps {

/// The exit code of a command that ran to its end: 0, or 3 when it ran but
/// did not do what was asked (an estimate with status failed, a campaign
/// with failed jobs). Errors are thrown instead (main: 1).
inline int& exitCode() {
  static int code = 0;
  return code;
}

void addInfoCommand(CLI::App& app);
void addStatsCommand(CLI::App& app);
void addTrajectoryCommand(CLI::App& app);
void addRenderCommand(CLI::App& app);
void addTrackCommand(CLI::App& app);
void addEvaluateTracksCommand(CLI::App& app);
void addEvaluateCommand(CLI::App& app);
void addCampaignCommand(CLI::App& app);
void addReportCommand(CLI::App& app);
void addExportCommand(CLI::App& app);
void addImportCommand(CLI::App& app);
void addSimulateCommand(CLI::App& app);
void addEstimateCommand(CLI::App& app);
void addHealthCommand(CLI::App& app);
void addVideoCommand(CLI::App& app);

/// Every subcommand above, in the order `evio --help` lists them (main.cpp;
/// the command-line fuzzer, tests/fuzz/fuzz_cli.cpp).
void addAllCommands(CLI::App& app);

}  // namespace evio::apps

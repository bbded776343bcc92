#pragma once
/// @file plot_runner.h
/// Runs one of the matplotlib scripts in experiments/plots with Debian's
/// /usr/bin/python3 (which has python3-matplotlib; the python3 first on PATH
/// may not). The scripts folder is $EVIO_PLOTS_DIR if set, else
/// experiments/plots of the data folder (data_root.h).

#include <string>
#include <vector>

namespace evio::apps {

/// Runs `script` with `args`; returns an empty string on success, otherwise
/// one line saying what failed (the caller prints it as a warning or error).
std::string runPlotScript(const std::string& script, const std::vector<std::string>& args);

}  // namespace evio::apps

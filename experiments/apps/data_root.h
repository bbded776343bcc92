#pragma once
/// @file data_root.h
/// Where `evio` finds the files it ships: sensor, scene and trajectory
/// presets, scenarios, campaigns, estimator configurations and plot scripts.
///
/// They live in one folder laid out like the repository
/// (`scenes/presets/…`, `experiments/scenarios/…`, `estimator/config/…`,
/// `experiments/plots/…`), found relative to the binary itself:
///   `<prefix>/bin/evio`  →  `<prefix>/share/evio`
/// `cmake --install` and the Debian package install that layout; the build
/// tree has it too (`build/<preset>/share/evio/<folder>` are links into the
/// source tree, made at configure time). So the binary runs from any working
/// folder and nothing of the source tree is compiled in. The environment
/// variable `EVIO_DATA_DIR` replaces the folder (e.g. a copy being edited).

#include <filesystem>
#include <string>

namespace evio::apps {

/// The data folder: $EVIO_DATA_DIR if set (it must be a folder), else the
/// one given to setDefaultDataRoot, else `share/evio` beside the binary's
/// folder. Throws evio::Error naming the path if that folder does not exist.
std::filesystem::path dataRoot();

/// Replaces the binary-relative default (the Python module: its data folder
/// is relative to the module's file, not to the python3 binary).
void setDefaultDataRoot(const std::filesystem::path& folder);

/// `path` as given if it exists or is absolute, else `dataRoot() / path` if
/// that exists, else `path` unchanged (the caller's error then names it).
std::string resolveDataPath(const std::string& path);

}  // namespace evio::apps

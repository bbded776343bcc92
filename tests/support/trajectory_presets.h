#pragma once
/// @file trajectory_presets.h
/// The preset files of trajectories/presets/ (EVIO_TRAJECTORY_PRESET_DIR is
/// set by the test's CMakeLists), for tests that run over every preset.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

namespace evio::test {

inline std::string trajectoryPresetDir() { return EVIO_TRAJECTORY_PRESET_DIR; }

/// Sorted file names (without folder) of every preset.
inline std::vector<std::string> trajectoryPresetFiles() {
  std::vector<std::string> names;
  for (const auto& entry : std::filesystem::directory_iterator(trajectoryPresetDir()))
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

inline std::string trajectoryPresetPath(const std::string& name) {
  return (std::filesystem::path(trajectoryPresetDir()) / name).string();
}

/// A gtest-safe test name from a file name ("hover_oscillation.yaml" → "hover_oscillation").
inline std::string presetTestName(const std::string& file) {
  std::string s = std::filesystem::path(file).stem().string();
  for (auto& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

}  // namespace evio::test

#pragma once
/// @file trajectory_factory.h
/// Builds a trajectory from a YAML map whose `type` names the preset
/// (hover, rotation_only, circle, six_dof, translation, flight,
/// lava_tube_entry, from_file); the other keys are that preset's Options
/// (unknown keys are an error naming file and line). The files in
/// trajectories/presets/ are such maps; a scenario can embed one as a
/// section and pass its path.

#include <memory>
#include <string>
#include <vector>

#include "evio/core/io/config.h"
#include "evio/trajectories/continuous_trajectory.h"

namespace evio {

/// The preset types, in documentation order.
const std::vector<std::string>& trajectoryTypes();

/// From the map at dotted `path` of `doc` (the root when empty). A relative
/// `file` of from_file is resolved from the folder of doc.file.
std::unique_ptr<ContinuousTrajectory> makeTrajectory(const config::Document& doc,
                                                     const std::string& path = "");

/// From a preset file, after applying `--set`-style overrides ("seed=3").
std::unique_ptr<ContinuousTrajectory> makeTrajectory(const std::string& yaml_file,
                                                     const std::vector<std::string>& overrides = {});

}  // namespace evio

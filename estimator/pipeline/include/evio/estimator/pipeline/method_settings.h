#pragma once
/// @file method_settings.h
/// Settings one method takes on top of a configuration shared by all
/// methods: a top-level section named after the method (method.h), e.g.
///
///   backend:
///     msckf_iterations: 3
///   klt-vio:              # KLT-VIO only
///     backend:
///       msckf_rotation_rows: true
///
/// The running method's section is merged into the document, key by key,
/// over the shared settings; every method's section is then removed, so
/// PipelineOptions never sees them. A key set on the command line (--set)
/// keeps its value: the section does not override it.

#include <string_view>

#include "evio/core/io/config.h"

namespace evio::estimator {

/// Merges the section of `method` into `doc` and removes every method's
/// section. Throws Error naming the file and line when a section is not a
/// map.
void applyMethodSettings(config::Document& doc, std::string_view method);

}  // namespace evio::estimator

#pragma once
/// @file bag_file.h
/// Opening ROS 1 bags with librosbag_storage, and turning the library's
/// exceptions into one evio::Error that names the bag and what is wrong.

#include <string>

#include <rosbag/bag.h>

namespace evio::bags::detail {

/// Switches off the ROS libraries' console output (console_bridge), which
/// would otherwise print beside evio's own one-line errors.
void silenceRosLogging();

/// Opens `path` for reading. Throws evio::Error naming the file when it is
/// missing, not a regular file, not a ROS 1 bag (version 2.0), or truncated
/// or unindexed (the index is at the end of a bag).
void openForReading(rosbag::Bag& bag, const std::string& path);

/// Rethrows the exception being handled as evio::Error
/// "<bag>: <context>: <what is wrong>". An evio::Error is prefixed the same
/// way; the library's exceptions are named by what they mean (truncated,
/// corrupt compressed chunk, message shorter than its type, ...).
[[noreturn]] void rethrowAsError(const std::string& bag, const std::string& context);

}  // namespace evio::bags::detail

#pragma once
/// @file exr_file.h
/// OpenEXR images of 32-bit float channels (radiance, depth, flow, heightmaps).
/// Lossless ZIP compression; values are stored bit-exactly.

#include <opencv2/core/mat.hpp>
#include <string>
#include <utility>
#include <vector>

namespace evio::io {

/// A named single-channel float image (CV_32FC1).
using ExrChannel = std::pair<std::string, cv::Mat>;

/// Writes the channels (each CV_32FC1, all of one size, names unique and
/// non-empty) as one FLOAT EXR file, atomically. Throws Error naming the file.
void writeExr(const std::string& path, const std::vector<ExrChannel>& channels);

/// Reads every channel of an EXR file as CV_32FC1 (HALF and UINT channels are
/// converted), sorted by name. Throws Error naming the file when it is missing
/// or not a valid EXR file.
std::vector<ExrChannel> readExr(const std::string& path);

/// Reads one channel: `name` if given, else the first of "Y", "R", "Z",
/// "depth", "height" present, else the only channel. Throws naming the file
/// and the channel otherwise.
cv::Mat readExrChannel(const std::string& path, const std::string& name = "");

}  // namespace evio::io

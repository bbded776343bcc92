#pragma once
/// @file image_file.h
/// Grayscale images for textures and heightmaps (PNG, JPEG, EXR) and PNG
/// previews. Colour is reduced to luminance Y = 0.2126 R + 0.7152 G + 0.0722 B
/// (Rec. 709): the simulated sensors are monochrome.

#include <opencv2/core/mat.hpp>
#include <string>

namespace evio::io {

enum class PixelScale {
  kNormalized,  ///< integer images are divided by their maximum (255 or 65535) → [0, 1]
  kRaw,         ///< integer values are kept (e.g. a 16-bit heightmap in its own units)
};

/// Reads an image as one float channel (CV_32FC1). `.exr` goes through
/// OpenEXR (channel Y, R, ... see readExrChannel; PixelScale does not apply),
/// anything else through OpenCV (8- or 16-bit). Throws Error naming the file
/// when it is missing or cannot be decoded.
cv::Mat readGrayImage(const std::string& path, PixelScale scale = PixelScale::kNormalized);

/// Writes an 8- or 16-bit, 1-, 3- or 4-channel image as PNG, atomically.
void writePng(const std::string& path, const cv::Mat& image);

}  // namespace evio::io

#pragma once
/// @file png_codec.h
/// PNG in memory through libpng, the format of every frame evio reads and
/// writes. Kept apart from OpenCV's imgcodecs (which reaches the other image
/// formats through the media module, media_module.h) so that reading frames
/// loads no more than libpng and zlib.

#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>

namespace evio::io {

/// True when `bytes` start with the eight-byte PNG signature.
bool isPng(std::string_view bytes);

/// Decodes a PNG as OpenCV's imdecode(IMREAD_UNCHANGED) does: grey → CV_8UC1 or
/// CV_16UC1 (depths below 8 expanded to 8 bits; a tRNS chunk ignored), grey
/// with alpha → 4 channels, colour or palette → BGR, with alpha or tRNS →
/// BGRA; 16-bit samples in host order; at most 2³⁰ pixels, as OpenCV. Throws Error naming `path` when the data is
/// not a valid PNG (bad signature, CRC, truncation, unsupported layout).
cv::Mat decodePng(std::string_view bytes, const std::string& path);

/// Encodes an 8- or 16-bit image with 1 (grey), 3 (BGR) or 4 (BGRA) channels
/// as PNG with OpenCV imencode's default settings (Sub filter, zlib level 1,
/// RLE strategy: frames are written at the simulator's pace), so the bytes are
/// those imencode writes with the same libpng and zlib. Throws Error naming
/// `path` otherwise.
std::string encodePng(const cv::Mat& image, const std::string& path);

}  // namespace evio::io

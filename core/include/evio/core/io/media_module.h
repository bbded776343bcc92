#pragma once
/// @file media_module.h
/// The heavy codecs live in a module loaded on first use, `libevio_media.so`:
/// image formats other than PNG and EXR (OpenCV's imgcodecs: JPEG, TIFF, …),
/// GDAL rasters (GeoTIFF DTMs) and video encoding (OpenCV's videoio over
/// FFmpeg). Linked into `evio` they would map about 180 more shared libraries
/// at every start (about 0.17 CPU s on the reference machine, 6 % of a 12 s
/// EKLT-VIO run); as a module only the commands that meet such a file pay.
///
/// Where it is looked for:
///   1. `$EVIO_MEDIA_MODULE`, a path to the module file, if set (the tests
///      set it; nothing else is tried then);
///   2. beside the running program's folder, `<bin>/../<libdir>/evio/`
///      (an installed `evio`, the Debian package's, and `build/<preset>/bin/evio`);
///   3. the configured install prefix's `<libdir>/evio/` (the Python module).
/// No build-tree path is compiled in: an installed binary names no source folder.

#include <opencv2/core/mat.hpp>
#include <cstddef>
#include <string>
#include <string_view>

#include "evio/core/io/raster_file.h"

namespace evio::io::media {

/// A video file being written by the module (OpenCV VideoWriter, FFmpeg).
class VideoEncoder {
 public:
  virtual ~VideoEncoder() = default;
  /// Appends one CV_8UC3 BGR frame of the size given when opening.
  virtual void write(const cv::Mat& bgr) = 0;
  /// Finishes the file (trailer, index).
  virtual void release() = 0;
};

/// The module's table of entry points. Errors come back as false (or null)
/// with a message; the caller turns them into evio::Error naming its file.
struct Api {
  int abi_version;
  /// Any format OpenCV's imdecode reads, with IMREAD_UNCHANGED.
  bool (*decode_image)(const unsigned char* bytes, std::size_t size, cv::Mat* image, std::string* error);
  /// Band `band` (1-based) as CV_32FC1 with its geotransform and no-data value.
  bool (*read_raster)(const std::string& path, int band, Raster* raster, std::string* error);
  /// A single-band Float32 GeoTIFF, north up, origin 0, written to `path` directly.
  bool (*write_geotiff)(const std::string& path, const cv::Mat& values, double pixel_size_m, std::string* error);
  /// An encoder for `fourcc` ("avc1", "mp4v", …) at `fps`, or null when it cannot open.
  VideoEncoder* (*open_video)(const std::string& path, const char* fourcc, double fps, int width, int height);
};

/// Bumped whenever Api changes, so a module from another build is refused.
inline constexpr int kAbiVersion = 1;
/// The module's one exported symbol: `extern "C" const Api* evio_media_api()`.
inline constexpr const char* kEntryPoint = "evio_media_api";

/// Loads the module once (thread-safe) and returns its table. Throws Error
/// naming `needed_for` (the file that needs it) and every path tried when the
/// module cannot be found or loaded.
const Api& api(const std::string& needed_for);

/// Decodes an image file's bytes as OpenCV's imdecode(IMREAD_UNCHANGED):
/// PNG here (png_codec.h), any other format through the module. Throws Error
/// naming `path` when the bytes cannot be decoded.
cv::Mat decodeImage(std::string_view bytes, const std::string& path);

}  // namespace evio::io::media

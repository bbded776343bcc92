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
///   2. the path given to setModulePath (the Python package: relative to
///      itself, in the build tree and once installed);
///   3. beside the running program's folder, `<bin>/../<libdir>/evio/`
///      (an installed `evio`, the Debian package's, and `build/<preset>/bin/evio`).
/// No absolute path is compiled in: an installed binary names no source
/// folder, and never loads the module of another installation. A module is
/// taken only from the build that made it (the build identifier and the
/// layouts of the types it exchanges must match).

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
  /// The build identifier (evio and OpenCV versions, compiler: the macro
  /// EVIO_MEDIA_BUILD_ID that core/CMakeLists.txt gives both sides) and the
  /// layouts the two sides must share; checked before any other member is used.
  const char* build_id;
  std::size_t api_size;
  std::size_t raster_size;
  std::size_t mat_size;
  /// Any format OpenCV's imdecode reads, with IMREAD_UNCHANGED.
  bool (*decode_image)(const unsigned char* bytes, std::size_t size, cv::Mat* image, std::string* error);
  /// Band `band` (1-based) as CV_32FC1 with its geotransform and no-data value.
  bool (*read_raster)(const std::string& path, int band, Raster* raster, std::string* error);
  /// A single-band Float32 GeoTIFF, north up, origin 0, written to `path` directly.
  bool (*write_geotiff)(const std::string& path, const cv::Mat& values, double pixel_size_m, std::string* error);
  /// An encoder for `fourcc` ("avc1", "mp4v", …) at `fps`, or null when it cannot open.
  VideoEncoder* (*open_video)(const std::string& path, const char* fourcc, double fps, int width, int height);
};

/// The module's one exported symbol: `extern "C" const Api* evio_media_api()`.
inline constexpr const char* kEntryPoint = "evio_media_api";

/// Loads the module once (thread-safe) and returns its table. Throws Error
/// naming `needed_for` (the file that needs it) and every path tried when the
/// module cannot be found or loaded.
const Api& api(const std::string& needed_for);

/// Where to look for the module after $EVIO_MEDIA_MODULE (the Python package
/// calls it at import). Has no effect once the module is loaded.
void setModulePath(const std::string& path);

/// Decodes an image file's bytes as OpenCV's imdecode(IMREAD_UNCHANGED):
/// PNG here (png_codec.h), the other formats OpenCV reads through the module.
/// Bytes with no image signature OpenCV knows are refused here, without
/// loading the module. Throws Error naming `path` when the bytes cannot be
/// decoded.
cv::Mat decodeImage(std::string_view bytes, const std::string& path);

}  // namespace evio::io::media

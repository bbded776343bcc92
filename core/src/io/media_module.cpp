#include "evio/core/io/media_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <system_error>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/png_codec.h"

// Set per source file by core/CMakeLists.txt.
#ifndef EVIO_MEDIA_BUILD_ID
#error "EVIO_MEDIA_BUILD_ID (the build identifier both sides share) is not defined"
#endif
#ifndef EVIO_MEDIA_FROM_BIN
#error "EVIO_MEDIA_FROM_BIN (the module's path relative to the program's folder) is not defined"
#endif

namespace evio::io::media {

namespace {

namespace fs = std::filesystem;

std::mutex& pathMutex() {
  static std::mutex m;
  return m;
}

std::string& explicitPath() {
  static std::string path;
  return path;
}

std::vector<std::string> candidatePaths() {
  if (const char* forced = std::getenv("EVIO_MEDIA_MODULE"); forced && *forced) return {forced};
  std::vector<std::string> paths;
  {
    const std::lock_guard<std::mutex> lock(pathMutex());
    if (!explicitPath().empty()) paths.push_back(explicitPath());
  }
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back((program.parent_path() / EVIO_MEDIA_FROM_BIN).lexically_normal().string());
  return paths;
}

/// Why a module file is not this build's, or empty when it is.
std::string mismatch(const Api& table) {
  if (!table.build_id || std::strcmp(table.build_id, EVIO_MEDIA_BUILD_ID) != 0)
    return std::string("built as '") + (table.build_id ? table.build_id : "?") + "', this evio is '" + EVIO_MEDIA_BUILD_ID + "'";
  if (table.api_size != sizeof(Api) || table.raster_size != sizeof(Raster) || table.mat_size != sizeof(cv::Mat))
    return "its type layouts differ from this evio's";
  return {};
}

/// The loaded table, or the reason there is none.
struct Loaded {
  const Api* api = nullptr;
  std::string failure;
};

Loaded load() {
  std::string tried;
  for (const std::string& candidate : candidatePaths()) {
    std::error_code ec;
    // Absolute, so that dlopen takes the file named and never searches the library path.
    const std::string path = fs::absolute(candidate, ec).lexically_normal().string();
    tried += "\n  " + path;
    if (ec || !fs::is_regular_file(path, ec)) {
      tried += " (missing)";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      tried += std::string(" (") + (why ? why : "dlopen failed") + ")";
      continue;
    }
    // Never closed, not even when refused: its libraries stay mapped until exit.
    using Entry = const Api* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, kEntryPoint));
    if (!entry) {
      const char* why = dlerror();
      tried += std::string(" (not an evio media module: ") + (why ? why : "no entry point") + ")";
      continue;
    }
    const Api* table = entry();
    const std::string why = table ? mismatch(*table) : std::string("no table");
    if (!why.empty()) {
      tried += " (a module of another evio build: " + why + ")";
      continue;
    }
    return {table, {}};
  }
  return {nullptr, "tried:" + tried};
}

bool startsWith(std::string_view bytes, std::string_view prefix) {
  return bytes.size() >= prefix.size() && bytes.compare(0, prefix.size(), prefix) == 0;
}

/// True when the bytes start like a format OpenCV's imgcodecs reads (BMP,
/// JPEG, JPEG 2000, WebP, PNM/PAM, PFM, Sun raster, TIFF, OpenEXR, Radiance
/// HDR, DICOM), so that nothing else loads the module only to be refused.
bool hasImageSignature(std::string_view b) {
  using namespace std::string_view_literals;
  if (startsWith(b, "BM"sv) || startsWith(b, "\xFF\xD8\xFF"sv)) return true;                      // BMP, JPEG
  if (startsWith(b, "\xFF\x4F\xFF\x51"sv) || startsWith(b, "\x00\x00\x00\x0CjP  \r\n\x87\n"sv)) return true;  // JPEG 2000
  if (startsWith(b, "RIFF"sv) && b.size() >= 12 && b.compare(8, 4, "WEBP"sv) == 0) return true;    // WebP
  if (b.size() >= 2 && b[0] == 'P' && b[1] >= '1' && b[1] <= '7') return true;                   // PBM/PGM/PPM/PAM
  if (startsWith(b, "PF"sv) || startsWith(b, "Pf"sv)) return true;                                  // PFM
  if (startsWith(b, "\x59\xA6\x6A\x95"sv)) return true;                                           // Sun raster
  if (startsWith(b, "II*\0"sv) || startsWith(b, "MM\0*"sv) || startsWith(b, "II+\0"sv) || startsWith(b, "MM\0+"sv))
    return true;                                                                                  // TIFF, BigTIFF
  if (startsWith(b, "\x76\x2F\x31\x01"sv)) return true;                                           // OpenEXR
  if (startsWith(b, "#?RADIANCE"sv) || startsWith(b, "#?RGBE"sv)) return true;                     // Radiance HDR
  return b.size() >= 132 && b.compare(128, 4, "DICM"sv) == 0;                                     // DICOM
}

}  // namespace

void setModulePath(const std::string& path) {
  const std::lock_guard<std::mutex> lock(pathMutex());
  explicitPath() = path;
}

const Api& api(const std::string& needed_for) {
  static const Loaded loaded = load();
  if (!loaded.api)
    throw Error(needed_for + ": needs evio's media module libevio_media.so (image formats other than PNG and EXR, "
                "GDAL rasters, video), which could not be loaded (EVIO_MEDIA_MODULE names it); " + loaded.failure);
  return *loaded.api;
}

cv::Mat decodeImage(std::string_view bytes, const std::string& path) {
  if (isPng(bytes)) return decodePng(bytes, path);
  if (bytes.empty()) throw Error::inFile(path, 0, "not a readable image (the file is empty)");
  if (!hasImageSignature(bytes))
    throw Error::inFile(path, 0, "not a readable image (no signature of an image format OpenCV reads)");
  cv::Mat image;
  std::string error;
  if (!api(path).decode_image(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), &image, &error))
    throw Error::inFile(path, 0, error);
  return image;
}

}  // namespace evio::io::media

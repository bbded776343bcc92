#include "evio/core/io/media_module.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <vector>

#include "evio/core/error.h"
#include "evio/core/io/png_codec.h"

// Set per source file by core/CMakeLists.txt.
#ifndef EVIO_MEDIA_FROM_BIN
#error "EVIO_MEDIA_FROM_BIN (the module's path relative to the program's folder) is not defined"
#endif
#ifndef EVIO_MEDIA_INSTALLED
#error "EVIO_MEDIA_INSTALLED (the module's installed path) is not defined"
#endif

namespace evio::io::media {

namespace {

namespace fs = std::filesystem;

std::vector<std::string> candidatePaths() {
  if (const char* forced = std::getenv("EVIO_MEDIA_MODULE"); forced && *forced) return {forced};
  std::vector<std::string> paths;
  std::error_code ec;
  const fs::path program = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) paths.push_back((program.parent_path() / EVIO_MEDIA_FROM_BIN).lexically_normal().string());
  paths.emplace_back(EVIO_MEDIA_INSTALLED);
  return paths;
}

/// The loaded table, or the reason there is none.
struct Loaded {
  const Api* api = nullptr;
  std::string failure;
};

Loaded load() {
  std::string tried;
  for (const std::string& path : candidatePaths()) {
    tried += "\n  " + path;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      tried += " (missing)";
      continue;
    }
    void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
      const char* why = dlerror();
      tried += std::string(" (") + (why ? why : "dlopen failed") + ")";
      continue;
    }
    using Entry = const Api* (*)();
    auto entry = reinterpret_cast<Entry>(dlsym(handle, kEntryPoint));
    const Api* table = entry ? entry() : nullptr;
    if (!table || table->abi_version != kAbiVersion) {
      tried += " (not a module of this evio build)";
      dlclose(handle);
      continue;
    }
    return {table, {}};  // never closed: its libraries stay mapped until exit
  }
  return {nullptr, "tried:" + tried};
}

}  // namespace

const Api& api(const std::string& needed_for) {
  static const Loaded loaded = load();
  if (!loaded.api)
    throw Error(needed_for + ": needs evio's media module libevio_media.so (image formats other than PNG and EXR, "
                "GDAL rasters, video), which could not be loaded (EVIO_MEDIA_MODULE names it); " + loaded.failure);
  return *loaded.api;
}

cv::Mat decodeImage(std::string_view bytes, const std::string& path) {
  if (isPng(bytes)) return decodePng(bytes, path);
  cv::Mat image;
  std::string error;
  if (!api(path).decode_image(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size(), &image, &error))
    throw Error::inFile(path, 0, error);
  return image;
}

}  // namespace evio::io::media

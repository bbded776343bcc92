#include "data_root.h"

#include <cstdlib>
#include <string>
#include <system_error>

#include "evio/core/error.h"

#ifndef EVIO_DATA_FROM_BIN
#define EVIO_DATA_FROM_BIN "../share/evio"  // the data folder seen from the binary's folder
#endif

namespace evio::apps {

namespace fs = std::filesystem;

namespace {

/// The folder of the running binary (/proc/self/exe, symlinks resolved).
fs::path binaryFolder() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot locate the evio binary (/proc/self/exe): " + ec.message());
  return exe.parent_path();
}

fs::path& defaultDataRoot() {
  static fs::path root;  // empty: relative to the binary
  return root;
}

}  // namespace

void setDefaultDataRoot(const fs::path& folder) { defaultDataRoot() = folder; }

fs::path dataRoot() {
  if (const char* env = std::getenv("EVIO_DATA_DIR"); env != nullptr && *env != '\0') {
    std::error_code ec;
    if (!fs::is_directory(env, ec)) throw Error("EVIO_DATA_DIR: not a folder: " + std::string(env));
    return fs::path(env);
  }
  const fs::path root = !defaultDataRoot().empty() ? defaultDataRoot()
                                                    : (binaryFolder() / EVIO_DATA_FROM_BIN).lexically_normal();
  std::error_code ec;
  if (!fs::is_directory(root, ec))
    throw Error("evio's data folder is missing: " + root.string() +
                " (install with `cmake --install`, or set EVIO_DATA_DIR to a folder laid out like the repository)");
  return root;
}

std::string resolveDataPath(const std::string& path) {
  std::error_code ec;
  if (fs::path(path).is_absolute() || fs::exists(path, ec)) return path;
  const fs::path in_data = dataRoot() / path;
  if (fs::exists(in_data, ec)) return in_data.string();
  return path;
}

}  // namespace evio::apps

#pragma once
/// @file atomic_file.h
/// Atomic writes: everything is written to a temporary file beside the target
/// and renamed onto it only when complete, so a killed run never leaves a
/// half-written result under the final name.

#include <cstdio>
#include <string>
#include <string_view>

#include "evio/core/io/staged_folder.h"

namespace evio::io {

/// A file being written. `commit()` flushes, closes and renames the temporary
/// onto `path`; destruction without commit removes the temporary.
class AtomicFile {
 public:
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Appends raw bytes. Throws Error on a write failure (e.g. disk full).
  void write(std::string_view bytes);
  /// Makes the file visible under its final name. Throws on failure.
  void commit();

  const std::string& path() const { return path_; }
  const std::string& temporaryPath() const { return tmp_path_; }

 private:
  std::string path_;
  std::string tmp_path_;
  std::FILE* file_ = nullptr;
  InterruptCleanup cleanup_;  ///< the temporary is removed on SIGINT/SIGTERM
};

/// Writes `content` to `path` atomically.
void writeFileAtomic(const std::string& path, std::string_view content);

/// A temporary path beside `path` unique to this process and call
/// ("<path>.tmp.<pid>.<n>"), for writers that produce the file themselves (HDF5).
std::string temporaryPathFor(const std::string& path);

/// Renames `from` onto `to` (atomic on one file system); throws on failure.
void renameFile(const std::string& from, const std::string& to);

/// Reads a whole (small) text file; throws Error naming the file when missing,
/// not a regular file, or larger than `max_bytes`.
std::string readFile(const std::string& path, std::size_t max_bytes = 256u << 20);

}  // namespace evio::io

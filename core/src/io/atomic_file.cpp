#include "evio/core/io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "evio/core/error.h"

namespace evio::io {

namespace {
std::atomic<unsigned> g_tmp_counter{0};  // only makes names unique; no state
}

std::string temporaryPathFor(const std::string& path) {
  return path + ".tmp." + std::to_string(::getpid()) + "." + std::to_string(g_tmp_counter++);
}

void renameFile(const std::string& from, const std::string& to) {
  faultPoint(to);
  if (std::rename(from.c_str(), to.c_str()) != 0)
    throw Error::inFile(to, 0, std::string("cannot rename temporary file: ") + std::strerror(errno));
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), tmp_path_(temporaryPathFor(path_)) {
  faultPoint(path_);
  cleanup_ = InterruptCleanup(tmp_path_);
  file_ = std::fopen(tmp_path_.c_str(), "wb");
  if (!file_) throw Error::inFile(path_, 0, std::string("cannot create file: ") + std::strerror(errno));
  std::setvbuf(file_, nullptr, _IOFBF, 1 << 20);
}

AtomicFile::~AtomicFile() {
  if (file_) {
    std::fclose(file_);
    std::remove(tmp_path_.c_str());
  }
}

void AtomicFile::write(std::string_view bytes) {
  if (!file_) throw Error::inFile(path_, 0, "write after commit");
  faultPoint(path_);
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw Error::inFile(path_, 0, std::string("write failed: ") + std::strerror(errno));
}

void AtomicFile::commit() {
  if (!file_) throw Error::inFile(path_, 0, "committed twice");
  const bool ok = std::fflush(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) {
    std::remove(tmp_path_.c_str());
    throw Error::inFile(path_, 0, std::string("write failed while closing: ") + std::strerror(errno));
  }
  try {
    renameFile(tmp_path_, path_);
  } catch (...) {
    std::remove(tmp_path_.c_str());  // a failed rename leaves no temporary behind
    throw;
  }
  cleanup_.release();
}

void writeFileAtomic(const std::string& path, std::string_view content) {
  AtomicFile f(path);
  f.write(content);
  f.commit();
}

std::string readFile(const std::string& path, std::size_t max_bytes) {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (std::filesystem::exists(st) && !std::filesystem::is_regular_file(st))
    throw Error::inFile(path, 0, "not a regular file (a folder?)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error::inFile(path, 0, "cannot open file (missing or unreadable)");
  const auto size = std::filesystem::file_size(path, ec);
  if (!ec && size > max_bytes)
    throw Error::inFile(path, 0, "file too large (" + std::to_string(size) + " bytes; at most " +
                                     std::to_string(max_bytes) + " read whole)");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace evio::io

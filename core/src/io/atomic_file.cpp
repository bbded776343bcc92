#include "evio/core/io/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
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
  if (std::rename(from.c_str(), to.c_str()) != 0)
    throw Error::inFile(to, 0, std::string("cannot rename temporary file: ") + std::strerror(errno));
}

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), tmp_path_(temporaryPathFor(path_)) {
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
    throw Error::inFile(path_, 0, "write failed while closing");
  }
  renameFile(tmp_path_, path_);
}

void writeFileAtomic(const std::string& path, std::string_view content) {
  AtomicFile f(path);
  f.write(content);
  f.commit();
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error::inFile(path, 0, "cannot open file (missing or unreadable)");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace evio::io

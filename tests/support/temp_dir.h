#pragma once
/// @file temp_dir.h
/// A temporary folder removed when the test ends.

#include <filesystem>
#include <random>
#include <string>

namespace evio::test {

class TempDir {
 public:
  TempDir() {
    std::random_device rd;  // only for a unique folder name, never for data
    path_ = std::filesystem::temp_directory_path() /
            ("evio_test_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::string file(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace evio::test

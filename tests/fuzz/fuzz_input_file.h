#pragma once
// Writes a fuzzer input to a per-process temporary file, since the readers
// under test take paths (they stream from disk).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

namespace evio::fuzz {

inline std::string writeInput(const std::uint8_t* data, std::size_t size, const char* name) {
  static const std::string dir = [] {
    char tmpl[] = "/tmp/evio_fuzz_XXXXXX";
    const char* d = ::mkdtemp(tmpl);
    return std::string(d ? d : "/tmp");
  }();
  const std::string path = dir + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) __builtin_trap();
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  return path;
}

}  // namespace evio::fuzz

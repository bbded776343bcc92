// libFuzzer target: images.txt list reader (files it names will not exist,
// which must be an evio::Error too).
#include <filesystem>

#include "evio/core/error.h"
#include "evio/core/io/images_txt.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "images.txt");
  try {
    evio::io::readImageList(std::filesystem::path(path).parent_path().string());
  } catch (const evio::Error&) {
  }
  return 0;
}

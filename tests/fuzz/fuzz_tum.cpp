// libFuzzer target: TUM trajectory readers, plain and with covariance.
#include "evio/core/error.h"
#include "evio/core/io/tum.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "groundtruth.txt");
  try {
    evio::io::readTum(path);
  } catch (const evio::Error&) {
  }
  try {
    evio::io::readTumCovariance(path);
  } catch (const evio::Error&) {
  }
  return 0;
}

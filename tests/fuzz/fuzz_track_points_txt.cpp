// libFuzzer target: truth/track_points.txt reader (evio::Error or success, nothing else).
#include "evio/core/error.h"
#include "evio/core/io/track_points_txt.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "track_points.txt");
  try {
    (void)evio::io::readTrackPoints(path);
  } catch (const evio::Error&) {
  }
  return 0;
}

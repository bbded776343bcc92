// libFuzzer target: imu_state.txt reader (evio::Error or success, nothing else).
#include "evio/core/error.h"
#include "evio/core/io/imu_state_txt.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "imu_state.txt");
  try {
    (void)evio::io::readImuStateText(path);
  } catch (const evio::Error&) {
  }
  return 0;
}

// libFuzzer target: truth/event_labels.bin reader (evio::Error or success, nothing else).
#include "evio/core/error.h"
#include "evio/core/io/event_labels_bin.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "event_labels.bin");
  try {
    (void)evio::io::readEventLabels(path);
  } catch (const evio::Error&) {
  }
  return 0;
}

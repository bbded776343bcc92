// libFuzzer target: events.txt reader. Any input must either parse or throw
// evio::Error; nothing else (crash, hang, other exception) is acceptable.
#include "evio/core/error.h"
#include "evio/core/io/events_txt.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "events.txt");
  try {
    evio::io::EventTextReader reader(path, evio::io::SensorSize{240, 180});
    evio::EventArray chunk;
    while (reader.next(chunk, 7)) chunk.clear();
  } catch (const evio::Error&) {
  }
  return 0;
}

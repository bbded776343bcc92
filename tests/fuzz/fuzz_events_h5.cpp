// libFuzzer target: the HDF5 event reader (DSEC layout). Any input must open
// and stream or throw evio::Error; nothing else (crash, hang, other exception,
// an allocation sized by a corrupt header) is acceptable. Seeds
// (tests/fuzz/seeds/events_h5/, so mutations reach the datasets, the
// attributes and /ms_to_idx): 12 events at 1 ms steps in chunks of 4, written
// by evio::io::writeEventsH5 as uint32 times without checksum, int64 times
// with Fletcher-32, and gzip level 1 without the sensor-size attributes.
#include <algorithm>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "fuzz_input_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = evio::fuzz::writeInput(data, size, "events.h5");
  try {
    evio::io::EventH5Reader reader(path, 240, 180);
    evio::EventArray chunk;
    while (reader.next(chunk, 5)) {
    }
    // A time window through /ms_to_idx, and an index range at the end.
    const evio::TimeNs t0 = reader.tFirstNs();
    reader.readWindow(t0, t0 + (reader.tLastNs() - t0) / 2 + 1, chunk);
    const std::uint64_t n = reader.size();
    reader.read(n - std::min<std::uint64_t>(n, 3), std::min<std::uint64_t>(n, 3), chunk);
  } catch (const evio::Error&) {
  }
  return 0;
}

// truth/event_labels.bin (core/io/event_labels_bin.h): round trip, streaming,
// and every kind of bad file.
#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/event_labels_bin.h"
#include "temp_dir.h"

namespace evio::io {
namespace {

TEST(EventLabelsBin, RoundTripStreamedInPieces) {
  test::TempDir tmp;
  std::vector<std::uint8_t> all;
  EventLabelWriter w(tmp.file("l.bin"));
  for (int chunk = 0; chunk < 5; ++chunk) {
    std::vector<std::uint8_t> part(static_cast<std::size_t>(1000 + chunk * 37));
    for (std::size_t i = 0; i < part.size(); ++i) part[i] = static_cast<std::uint8_t>((i * 7 + chunk) % 4);
    w.append(part.data(), part.size());
    all.insert(all.end(), part.begin(), part.end());
  }
  EXPECT_FALSE(std::filesystem::exists(tmp.file("l.bin")));  // appears on close
  w.close();
  EXPECT_EQ(readEventLabels(tmp.file("l.bin")), all);
  const std::string raw = readFile(tmp.file("l.bin"));
  EXPECT_EQ(raw.substr(0, 8), "EVIOLBL1");
  EXPECT_EQ(raw.size(), 16 + all.size());
  writeEventLabels(tmp.file("empty.bin"), {});
  EXPECT_TRUE(readEventLabels(tmp.file("empty.bin")).empty());
}

TEST(EventLabelsBin, RejectsBadValuesAndFiles) {
  test::TempDir tmp;
  EventLabelWriter w(tmp.file("x.bin"));
  const std::uint8_t bad[2] = {1, 4};
  EXPECT_THROW(w.append(bad, 2), Error);
  writeEventLabels(tmp.file("ok.bin"), {0, 1, 2, 3});
  std::string raw = readFile(tmp.file("ok.bin"));
  writeFileAtomic(tmp.file("truncated.bin"), raw.substr(0, raw.size() - 1));
  writeFileAtomic(tmp.file("long.bin"), raw + "\x01");
  writeFileAtomic(tmp.file("magic.bin"), "EVIOLBL2" + raw.substr(8));
  writeFileAtomic(tmp.file("short.bin"), raw.substr(0, 10));
  raw[17] = 9;
  writeFileAtomic(tmp.file("value.bin"), raw);
  for (const char* f : {"truncated.bin", "long.bin", "magic.bin", "short.bin", "value.bin", "missing.bin"}) {
    try {
      readEventLabels(tmp.file(f));
      ADD_FAILURE() << f << " was accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace evio::io

#include "evio/core/io/tracks_txt.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "temp_dir.h"

namespace evio::io {
namespace {

TEST(TracksTxt, RoundTripIsExact) {
  test::TempDir dir;
  const std::vector<TrackSample> samples = {
      {0, 1'000'000'001, Vec2(10.25, 20.125)},
      {3, 1'000'000'002, Vec2(0.1 + 0.2, 1.0 / 3.0)},
      {0, 1'500'000'000, Vec2(-0.499, 179.4999999)},
      {12345678901, 0, Vec2(1e-9, 239.5)},
  };
  const std::string path = dir.file("tracks.txt");
  writeTracksText(path, samples, {"evio track test", "id t x y"});
  EXPECT_EQ(readTracksText(path), samples);
  EXPECT_NE(readFile(path).find("# id t x y"), std::string::npos);
}

TEST(TracksTxt, BadInputNamesFileLineAndColumn) {
  test::TempDir dir;
  const auto expectError = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir.file("bad.txt");
    writeFileAtomic(path, text);
    try {
      readTracksText(path);
      ADD_FAILURE() << "no error for: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectError("0 0.1 1 2\n0 0.2 1\n", "bad.txt:2");
  expectError("0 0.1 1 2 3\n", "expected 4 columns");
  expectError("-1 0.1 1 2\n", "id");
  expectError("1.5 0.1 1 2\n", "id");
  expectError("0 abc 1 2\n", "t");
  expectError("0 0.1 nan 2\n", "x");
  expectError("0 0.1 1 inf\n", "y");
  expectError("# c\n0 0.2 1 2\n1 0.1 1 2\n0 0.2 3 4\n", "bad.txt:4");  // track 0 repeats its time
  EXPECT_THROW(readTracksText(dir.file("missing.txt")), Error);
}

TEST(TracksTxt, WriterRejectsNonIncreasingTrackTimeAndLeavesNoFile) {
  test::TempDir dir;
  const std::string path = dir.file("tracks.txt");
  {
    TracksWriter w(path);
    w.append({1, 10, Vec2(1, 2)});
    w.append({2, 5, Vec2(1, 2)});  // other tracks may go back in time
    EXPECT_THROW(w.append({1, 10, Vec2(1, 2)}), Error);
    EXPECT_THROW(w.append({-4, 11, Vec2(1, 2)}), Error);
  }
  EXPECT_FALSE(std::filesystem::exists(path));
}

}  // namespace
}  // namespace evio::io

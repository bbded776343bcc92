// truth/track_points.txt (core/io/track_points_txt.h): bit-exact round trip
// and bad input with file:line and column.
#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/track_points_txt.h"
#include "temp_dir.h"

namespace evio::io {
namespace {

TEST(TrackPointsTxt, RoundTripIsBitExact) {
  test::TempDir tmp;
  std::vector<TrackPoint> points = {{0, Vec3(0.1, -2.0 / 3.0, 1e-17)}, {5, Vec3(-8.449999, 1e6, 3.14159265358979)},
                                    {2, Vec3::Zero()}};
  writeTrackPoints(tmp.file("p.txt"), points, {"a header"});
  EXPECT_EQ(readFile(tmp.file("p.txt")).substr(0, 11), "# a header\n");
  EXPECT_EQ(readTrackPoints(tmp.file("p.txt")), points);
}

TEST(TrackPointsTxt, RejectsBadInput) {
  test::TempDir tmp;
  EXPECT_THROW(writeTrackPoints(tmp.file("w.txt"), {{1, Vec3::Zero()}, {1, Vec3::Ones()}}), Error);
  EXPECT_THROW(writeTrackPoints(tmp.file("w.txt"), {{-1, Vec3::Zero()}}), Error);
  EXPECT_THROW(writeTrackPoints(tmp.file("w.txt"), {{0, Vec3(0, std::nan(""), 0)}}), Error);
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"0 1 2\n", ":1"}, {"0 1 2 3 4\n", ":1"}, {"# c\n0 1 2 3\n0 1 2 3\n", ":3: id"},
      {"-1 1 2 3\n", ":1: id"}, {"0 1 nan 3\n", ":1: py"}, {"x 1 2 3\n", ":1: id"}};
  for (const auto& [text, where] : cases) {
    writeFileAtomic(tmp.file("bad.txt"), text);
    try {
      readTrackPoints(tmp.file("bad.txt"));
      ADD_FAILURE() << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("bad.txt" + where), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace evio::io

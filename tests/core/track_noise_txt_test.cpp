#include "evio/core/io/track_noise_txt.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "temp_dir.h"

namespace evio::io {
namespace {

Mat2 cov(double xx, double xy, double yy) { return (Mat2() << xx, xy, xy, yy).finished(); }

TEST(TrackNoiseTxt, RoundTripIsExact) {
  test::TempDir dir;
  const std::vector<TrackNoiseSample> samples = {
      {0, 1'000'000'001, 1.0, Mat2::Zero()},
      {3, 1'000'000'002, 0.1 + 0.2, cov(4.0, 1.0 / 3.0, 25.0)},
      {0, 1'500'000'000, 0.6, cov(1e-300, 0.0, 4.0 + 1e-12)},
      {12345678901, 0, 0.0, cov(2.0, -2.0, 2.0)},  // singular: semi-definite is allowed
  };
  const std::string path = dir.file("t.txt.noise.txt");
  writeTrackNoiseText(path, samples, {"evio track test", "id t quality cov_xx cov_xy cov_yy"});
  EXPECT_EQ(readTrackNoiseText(path), samples);
  EXPECT_NE(readFile(path).find("# id t quality cov_xx cov_xy cov_yy"), std::string::npos);
}

TEST(TrackNoiseTxt, BadInputNamesFileLineAndColumn) {
  test::TempDir dir;
  const auto expectError = [&](const std::string& text, const std::string& needle) {
    const std::string path = dir.file("bad.txt");
    writeFileAtomic(path, text);
    try {
      readTrackNoiseText(path);
      ADD_FAILURE() << "no error for: " << text;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  expectError("0 0.1 1 4 0 4\n0 0.2 1 4 0\n", "bad.txt:2");
  expectError("0 0.1 1 4 0 4 7\n", "expected 6 columns");
  expectError("-1 0.1 1 4 0 4\n", "id");
  expectError("0 x 1 4 0 4\n", "t");
  expectError("0 0.1 1.5 4 0 4\n", "quality");
  expectError("0 0.1 1 nan 0 4\n", "cov_xx");
  expectError("0 0.1 1 4 0 inf\n", "cov_yy");
  expectError("0 0.1 1 1 3 1\n", "not positive semi-definite");
  expectError("0 0.1 1 -1 0 4\n", "not positive semi-definite");
}

TEST(TrackNoiseTxt, WriterRefusesWhatTheReaderWould) {
  test::TempDir dir;
  const std::string path = dir.file("w.txt");
  EXPECT_THROW(writeTrackNoiseText(path, {{-1, 0, 1.0, Mat2::Zero()}}), Error);
  EXPECT_THROW(writeTrackNoiseText(path, {{0, 0, 1.5, Mat2::Zero()}}), Error);
  EXPECT_THROW(writeTrackNoiseText(path, {{0, 0, 0.5, (Mat2() << 1, 0.5, 0.4, 1).finished()}}), Error);
  EXPECT_THROW(writeTrackNoiseText(path, {{0, 0, 0.5, cov(1, 3, 1)}}), Error);
}

}  // namespace
}  // namespace evio::io

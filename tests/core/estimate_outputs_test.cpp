// timing.txt and status.yaml: the estimator's side files read by `evio evaluate`.
#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/io/timing_txt.h"
#include "error_of.h"
#include "temp_dir.h"

namespace evio {
namespace {

using test::errorOf;

TEST(TimingText, RoundTripsAndStartsWithItsHeader) {
  std::vector<io::TimingSample> samples;
  for (int i = 0; i < 50; ++i)
    samples.push_back({TimeNs{500'000'000} + TimeNs{i} * 100'000'007, 0.013 * i + 0.25, std::int64_t{48'211} * i,
                       std::int64_t{(i * 37) % 61}});  // features go up and down, 0 included
  test::TempDir dir;
  io::writeTimingText(dir.file("timing.txt"), samples);
  EXPECT_EQ(io::readTimingText(dir.file("timing.txt")), samples);
  const std::string text = io::readFile(dir.file("timing.txt"));
  EXPECT_EQ(text.rfind("# t processing_s events features\n0.500000000 0.25 0 0\n0.600000007 0.263 48211 37\n", 0),
            0u)
      << text;
}

// Files written before the features column (3 columns) read with no count.
TEST(TimingText, ReadsThreeColumnFilesWithoutFeatures) {
  test::TempDir dir;
  io::writeFileAtomic(dir.file("timing.txt"), "# t processing_s events\n0.5 0.01 0\n0.6 0.05 1000\n");
  const std::vector<io::TimingSample> expected = {{500'000'000, 0.01, 0, std::nullopt},
                                                  {600'000'000, 0.05, 1000, std::nullopt}};
  EXPECT_EQ(io::readTimingText(dir.file("timing.txt")), expected);
}

TEST(TimingText, RejectsBadRowsWithFileLineAndColumn) {
  test::TempDir dir;
  const auto read = [&](const std::string& text) {
    return errorOf([&] {
      io::writeFileAtomic(dir.file("timing.txt"), text);
      io::readTimingText(dir.file("timing.txt"));
    });
  };
  const std::string file = dir.file("timing.txt");
  EXPECT_EQ(read("0.5 0.01 0\n0.6 0.05 1000\n"), "");
  EXPECT_EQ(read("0.5 0.01 0 0\n0.6 0.05 1000 45\n0.7 0.07 1100 12\n"), "");  // features may decrease
  EXPECT_NE(read("0.5 0.01 0\n0.5 0.05 10\n").find("timing.txt:2"), std::string::npos);  // t not increasing
  EXPECT_NE(read("0.5 0.05 0\n0.6 0.01 10\n").find("processing_s"), std::string::npos);   // decreasing
  EXPECT_NE(read("0.5 0.05 10\n0.6 0.06 9\n").find("events"), std::string::npos);         // decreasing
  EXPECT_NE(read("0.5 0.05 1.5\n").find("events"), std::string::npos);                    // not whole
  EXPECT_NE(read("0.5 -1 0\n").find("processing_s"), std::string::npos);
  EXPECT_NE(read("0.5 0.01\n").find("timing.txt:1"), std::string::npos);  // columns
  // The features column: a whole number >= 0, named with file, line and column.
  EXPECT_EQ(read("0.5 0.01 0 3\n0.6 0.05 10 2.5\n"), file + ":2: features: must be a whole number >= 0");
  EXPECT_EQ(read("0.5 0.01 0 -1\n"), file + ":1: features: must be a whole number >= 0");
  EXPECT_EQ(read("0.5 0.01 0 x\n"), file + ":1: features: not a finite number: 'x'");
  EXPECT_EQ(read("0.5 0.01 0 nan\n"), file + ":1: features: not a finite number: 'nan'");
  // Every row has the first row's column count; five columns are too many.
  EXPECT_EQ(read("0.5 0.01 0 3\n0.6 0.05 10\n"),
            file + ":2: timing.txt: expected 4 columns 't processing_s events features' (as on the first row), got 3");
  EXPECT_EQ(read("0.5 0.01 0\n0.6 0.05 10 3\n"),
            file + ":2: timing.txt: expected 3 columns 't processing_s events' (as on the first row), got 4");
  EXPECT_EQ(read("0.5 0.01 0 3 4\n"),
            file + ":1: timing.txt: expected 3 to 4 columns 't processing_s events features' (the last 1 optional), "
                   "got 4+");
  io::TimingWriter w(dir.file("w.txt"));
  w.append({1000, 0.5, 3, 0});
  EXPECT_THROW(w.append({1000, 0.6, 3, 0}), Error);
  EXPECT_THROW(w.append({2000, 0.4, 3, 0}), Error);
  EXPECT_THROW(w.append({2000, 0.6, 3, -1}), Error);          // negative count
  EXPECT_THROW(w.append({2000, 0.6, 3, std::nullopt}), Error);  // the writer always writes the column
}

TEST(StatusYaml, RoundTripsEveryField) {
  io::EstimateStatus s;
  s.code = io::EstimateStatus::Code::kDiverged;
  s.t_ns = 12'345'000'000;
  s.cause = "velocity above 100 m/s: \"bad\"";
  s.initialization_t_ns = 500'000'000;
  EXPECT_EQ(io::parseStatusYaml(io::formatStatusYaml(s)), s);
  io::EstimateStatus ok;
  EXPECT_EQ(io::parseStatusYaml(io::formatStatusYaml(ok)), ok);
  io::EstimateStatus degraded = s;
  degraded.code = io::EstimateStatus::Code::kDegraded;
  degraded.cause = "self-diagnosis: innovations 31 times their expectation";
  EXPECT_EQ(io::parseStatusYaml(io::formatStatusYaml(degraded)), degraded);
  test::TempDir dir;
  io::writeStatusYaml(dir.file("status.yaml"), s);
  EXPECT_EQ(io::readStatusYaml(dir.file("status.yaml")), s);
}

TEST(StatusYaml, RejectsBadFilesWithLineAndField) {
  const auto parse = [](const std::string& text) {
    return errorOf([&] { io::parseStatusYaml(text, "status.yaml"); });
  };
  EXPECT_EQ(parse("status: ok\n"), "");
  EXPECT_EQ(parse("status: failed\ntime_s: 3.5\ncause: no IMU\n"), "");
  EXPECT_NE(parse("status: diverged\n").find("time_s"), std::string::npos);  // time required
  EXPECT_NE(parse("status: degraded\n").find("time_s"), std::string::npos);
  EXPECT_NE(parse("status: exploded\ntime_s: 1\n").find("status.yaml:1"), std::string::npos);
  EXPECT_NE(parse("status: ok\ncolour: red\n").find("status.yaml:2"), std::string::npos);
  EXPECT_NE(parse("status: ok\nstatus: ok\n").find("duplicate"), std::string::npos);
  EXPECT_NE(parse("time_s: 1\n").find("status"), std::string::npos);
  EXPECT_NE(parse("status: failed\ntime_s: .nan\n").find("time_s"), std::string::npos);
  EXPECT_NE(parse("- a\n").find("status.yaml:1"), std::string::npos);
}

}  // namespace
}  // namespace evio

#include "evio/core/io/range_txt.h"

#include <gtest/gtest.h>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/random_stream.h"
#include "temp_dir.h"

namespace evio {
namespace {

TEST(RangeText, RoundTripsBitForBit) {
  RandomStream rng(5, "test");
  std::vector<io::RangeSample> samples;
  for (int i = 0; i < 300; ++i) {
    io::RangeSample s;
    s.t_ns = 2'000'000'000 + TimeNs{i} * 10'000'017;
    s.valid = rng.uniform() < 0.8;
    s.range_m = s.valid ? rng.uniform(0.05, 40.0) : 0.0;
    samples.push_back(s);
  }
  test::TempDir dir;
  io::writeRangeText(dir.file("range.txt"), samples, {"t range_m valid"});
  const auto back = io::readRangeText(dir.file("range.txt"));
  ASSERT_EQ(back.size(), samples.size());
  for (std::size_t i = 0; i < samples.size(); ++i) EXPECT_EQ(back[i], samples[i]) << i;
  EXPECT_EQ(io::readFile(dir.file("range.txt")).rfind("# t range_m valid\n", 0), 0u);
}

TEST(RangeText, RejectsBadRowsWithFileAndLine) {
  test::TempDir dir;
  const auto errorOf = [&](const std::string& text) -> std::string {
    io::writeFileAtomic(dir.file("r.txt"), text);
    try {
      io::readRangeText(dir.file("r.txt"));
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(errorOf("0.0 1.5 1\n0.1 0 0\n"), "");
  EXPECT_NE(errorOf("0.0 1.5 1\n0.0 1.5 1\n").find("r.txt:2"), std::string::npos);  // time not increasing
  EXPECT_NE(errorOf("0.0 1.5 2\n").find("valid"), std::string::npos);
  EXPECT_NE(errorOf("0.0 -1.5 1\n").find("range_m"), std::string::npos);
  EXPECT_NE(errorOf("0.0 nan 1\n").find("range_m"), std::string::npos);
  EXPECT_NE(errorOf("0.0 1.5\n").find("r.txt:1"), std::string::npos);  // columns
}

}  // namespace
}  // namespace evio

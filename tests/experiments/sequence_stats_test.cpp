#include "evio/experiments/sequence_stats.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

constexpr TimeNs kUs = 1000;

// 14 events on a 10x10 sensor, every figure known (t in ms, x, y, p):
// pixel (2,2) ON at 0, 2, 4, 20, 20.5 and OFF at 30; (8,8) ON at 100 and 205;
// (7,7) ON at 200; (0,9) OFF at 300; (5,0) OFF at 400 and (6,1) ON at 410
// (neighbours exactly 10 ms apart: not isolated); (0,5) ON at 600 and (0,6)
// ON at 610.000001 (1 ns more than 10 ms apart: both isolated).
void writeEvents(const std::string& folder) {
  EventArray ev;
  const struct { TimeNs t; int x, y; bool on; } list[] = {
      {0, 2, 2, true},           {2 * kNsPerMs, 2, 2, true}, {4 * kNsPerMs, 2, 2, true}, {20 * kNsPerMs, 2, 2, true},
      {20500 * kUs, 2, 2, true}, {30 * kNsPerMs, 2, 2, false}, {100 * kNsPerMs, 8, 8, true}, {200 * kNsPerMs, 7, 7, true},
      {205 * kNsPerMs, 8, 8, true}, {300 * kNsPerMs, 0, 9, false}, {400 * kNsPerMs, 5, 0, false},
      {410 * kNsPerMs, 6, 1, true}, {600 * kNsPerMs, 0, 5, true}, {610 * kNsPerMs + 1, 0, 6, true}};
  for (const auto& e : list) ev.push_back(e.t, static_cast<std::uint16_t>(e.x), static_cast<std::uint16_t>(e.y), e.on);
  io::writeEventsText(folder + "/events.txt", ev);
}

SequenceStatsOptions tenByTen() {
  SequenceStatsOptions o;
  o.width_px = 10;
  o.height_px = 10;
  return o;
}

TEST(SequenceStats, EventFiguresOfAKnownStreamAreExact) {
  test::TempDir dir;
  writeEvents(dir.path().string());
  const SequenceStats s = computeSequenceStats(dir.path().string(), tenByTen());
  const EventStreamStats& e = s.events;
  ASSERT_TRUE(e.present);
  EXPECT_FALSE(s.frames.present);
  EXPECT_EQ(e.count, 14u);
  EXPECT_EQ(e.on_count, 11u);
  EXPECT_EQ(e.t_last_ns, 610 * kNsPerMs + 1);
  // 61 whole 10 ms windows (the one holding 610.000001 ms is partial): counts
  // 3 2 1 1 2 1 1 1 1 in windows 0 2 3 10 20 30 40 41 60, 52 empty.
  ASSERT_EQ(e.window_counts.size(), 61u);
  EXPECT_EQ(e.window_counts[0], 3u);
  EXPECT_EQ(e.window_counts[20], 2u);
  EXPECT_DOUBLE_EQ(e.window_rate_hz.p50, 0.0);    // rank 31 of 61
  EXPECT_DOUBLE_EQ(e.window_rate_hz.p90, 100.0);  // rank 55: one event per 10 ms
  EXPECT_DOUBLE_EQ(e.window_rate_hz.max, 300.0);
  // Intervals: (2,2) ON 2, 2, 16, 0.5 ms; (8,8) ON 105 ms (a 0.1 % bin).
  EXPECT_EQ(e.interval_count, 5u);
  EXPECT_DOUBLE_EQ(e.interval_s.min, 0.0005);
  EXPECT_DOUBLE_EQ(e.interval_s.p1, 0.0005);
  EXPECT_DOUBLE_EQ(e.interval_s.p50, 0.002);  // rank 3 of 0.5 2 2 15.5 105
  EXPECT_NEAR(e.interval_s.max, 0.105, 0.105e-3);
  EXPECT_DOUBLE_EQ(e.interval_under_1ms_fraction, 0.2);
  // Bursts (gap 5 ms): (2,2) ON {0,2,4} {20,20.5}, then nine single events.
  EXPECT_EQ(e.burst_count, 11u);
  EXPECT_DOUBLE_EQ(e.events_per_burst.p50, 1.0);
  EXPECT_DOUBLE_EQ(e.events_per_burst.p90, 2.0);  // rank 10 of 1×9, 2, 3
  EXPECT_DOUBLE_EQ(e.events_per_burst.max, 3.0);
  // Isolated: (8,8)@100, (0,9)@300, (0,5)@600, (0,6)@610.000001.
  EXPECT_EQ(e.isolated_count, 4u);
  EXPECT_DOUBLE_EQ(e.isolated_rate_hz_per_pixel, 4.0 / (100.0 * 0.610000001));
  // Per pixel: 92 pixels 0, six 1, one 2, one 6.
  EXPECT_DOUBLE_EQ(e.pixel_count.p90, 0.0);
  EXPECT_DOUBLE_EQ(e.pixel_count.p99, 2.0);
  EXPECT_DOUBLE_EQ(e.pixel_count.max, 6.0);
  const JsonValue j = sequenceStatsJson(s);
  EXPECT_EQ(j.at("events.isolated_count")->text(), "4");
  EXPECT_TRUE(j.at("frames")->isNull());
  EXPECT_NE(formatSequenceStats(s).find("14 in 0.610 s"), std::string::npos);
}

TEST(SequenceStats, FrameFiguresOfKnownPixelsAreExact) {
  test::TempDir dir;
  const std::string folder = dir.path().string();
  const cv::Mat a = (cv::Mat_<std::uint8_t>(4, 4) << 0, 0, 10, 20, 0, 100, 50, 255, 30, 60, 200, 255, 40, 255, 0, 255);
  io::ImageFolderWriter frames(folder);
  frames.append(kNsPerSecond, a);
  frames.append(kNsPerSecond + 100 * kNsPerMs, cv::Mat(4, 4, CV_8UC1, cv::Scalar(128)));
  frames.close();
  const FrameStreamStats f = computeSequenceStats(folder).frames;
  ASSERT_TRUE(f.present);
  EXPECT_EQ(f.count, 2u);
  EXPECT_NEAR(f.rateHz(), 10.0, 1e-9);
  EXPECT_FALSE(f.exposure_s.has_value());
  EXPECT_EQ(f.histogram[255], 4u);
  EXPECT_EQ(f.histogram[128], 16u);
  EXPECT_DOUBLE_EQ(f.brightness_mean_dn, (1530.0 + 128.0 * 16) / 32);  // 1530: sum of frame a
  EXPECT_DOUBLE_EQ(f.fraction_at_0, 4.0 / 32);
  EXPECT_DOUBLE_EQ(f.fraction_at_255, 4.0 / 32);
  EXPECT_DOUBLE_EQ(f.max_dn.p50, 128.0);  // rank 1 of {128, 255}
  EXPECT_DOUBLE_EQ(f.max_dn.max, 255.0);
  EXPECT_DOUBLE_EQ(f.fraction_at_max, (4.0 / 16 + 1.0) / 2);
  EXPECT_DOUBLE_EQ(f.white_level_dn.max, 255.0);  // every DN present holds ≥ 0.5 % of 16 pixels
  EXPECT_DOUBLE_EQ(f.fraction_near_white, (4.0 / 16 + 1.0) / 2);
  // Frame a's interior Laplacians: −290, 365, 345, −435 (variance 131379.6875); frame b: 0.
  EXPECT_DOUBLE_EQ(f.laplacian_variance_dn2, 131379.6875 / 2);
}

TEST(SequenceStats, BadInputIsAnErrorSayingWhatIsMissing) {
  test::TempDir dir;
  try {
    computeSequenceStats(dir.file("nowhere"));
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("no such directory"), std::string::npos) << e.what();
  }
  try {
    computeSequenceStats(dir.path().string());
    FAIL() << "no error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("no events (events.h5 or events.txt)"), std::string::npos) << what;
    EXPECT_NE(what.find("no frames (images.txt)"), std::string::npos) << what;
  }
  SequenceStatsOptions bad;
  bad.burst_gap_s = 0.0;
  EXPECT_THROW(computeSequenceStats(dir.path().string(), bad), Error);
  writeEvents(dir.path().string());  // pixel (8,8) outside a 5x5 sensor
  SequenceStatsOptions small;
  small.width_px = small.height_px = 5;
  EXPECT_THROW(computeSequenceStats(dir.path().string(), small), Error);
}

}  // namespace
}  // namespace evio::experiments

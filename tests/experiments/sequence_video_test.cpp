#include "evio/experiments/sequence_video.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

// A 64x48 sequence of 1 s whose every pixel is known: frames of grey level
// 40 at t = 0 … 0.4 s and 200 from t = 0.5 s; a 20x20 block of ON events at
// t = 0.3 s and of OFF events at t = 0.7 s (left and right halves); one track
// standing still at (10, 10).
constexpr int kW = 64, kH = 48;

void writeSequence(const std::string& folder) {
  io::ImageFolderWriter frames(folder);
  for (int i = 0; i <= 10; ++i)
    frames.append(TimeNs(i) * 100 * kNsPerMs, cv::Mat(kH, kW, CV_8UC1, cv::Scalar(i < 5 ? 40 : 200)));
  frames.close();
  EventArray ev;
  for (int y = 20; y < 40; ++y)
    for (int x = 4; x < 24; ++x) ev.push_back(300 * kNsPerMs, x, y, true);
  for (int y = 20; y < 40; ++y)
    for (int x = 40; x < 60; ++x) ev.push_back(700 * kNsPerMs, x, y, false);
  io::writeEventsText(folder + "/events.txt", ev);
}

/// Mean of a channel over a sensor-pixel rectangle of the left (0) or right (1) panel.
double panelMean(const cv::Mat& bgr, int panel, cv::Rect sensor_rect, int scale) {
  cv::Rect r(sensor_rect.x * scale + panel * kW * scale, sensor_rect.y * scale, sensor_rect.width * scale,
             sensor_rect.height * scale);
  // Stay 2 px inside the block: the codec smears its edges.
  r.x += 2, r.y += 2, r.width -= 4, r.height -= 4;
  return cv::mean(bgr(r))[1];
}

TEST(SequenceVideo, FramesEventsAndTimingAreWhereTheSequenceSaysTheyAre) {
  test::TempDir dir;
  writeSequence(dir.path().string());
  VideoOptions options;
  options.fps = 10.0;
  options.window_s = 0.05;
  options.tracks = "none";
  const std::string out = dir.file("seq.mp4");
  const VideoSummary s = writeSequenceVideo(dir.path().string(), out, options);
  EXPECT_EQ(s.frames, 11u);  // t = 0, 0.1, …, 1.0 s
  EXPECT_EQ(s.width, 2 * kW * options.scale);
  EXPECT_EQ(s.height, kH * options.scale);
  EXPECT_EQ(s.events, 800u);  // each block falls in exactly one 50 ms window ending on a video frame

  cv::VideoCapture in(out, cv::CAP_FFMPEG);
  ASSERT_TRUE(in.isOpened());
  std::vector<cv::Mat> video;
  for (cv::Mat f; in.read(f);) video.push_back(f.clone());
  ASSERT_EQ(video.size(), 11u);
  ASSERT_EQ(video[0].cols, s.width);
  ASSERT_EQ(video[0].rows, s.height);
  // Tolerance 12 DN: lossy compression of flat blocks (measured error is a few DN).
  const cv::Rect block_on(4, 20, 20, 20), block_off(40, 20, 20, 20), frame_area(30, 25, 30, 20);
  for (std::size_t k = 0; k < video.size(); ++k) {
    SCOPED_TRACE("video frame " + std::to_string(k));
    EXPECT_NEAR(panelMean(video[k], 0, frame_area, options.scale), k < 5 ? 40 : 200, 12);
    EXPECT_NEAR(panelMean(video[k], 1, block_on, options.scale), k == 3 ? 255 : 128, 12);
    EXPECT_NEAR(panelMean(video[k], 1, block_off, options.scale), k == 7 ? 0 : 128, 12);
  }
}

TEST(SequenceVideo, BadInputIsOneClearErrorAndNoFile) {
  test::TempDir dir;
  writeSequence(dir.path().string());
  VideoOptions options;
  EXPECT_THROW(writeSequenceVideo(dir.path().string(), dir.file("seq.gif"), options), Error);
  options.fps = 0;
  EXPECT_THROW(writeSequenceVideo(dir.path().string(), dir.file("seq.mp4"), options), Error);
  options = VideoOptions();
  options.tracks = dir.file("missing.txt");
  EXPECT_THROW(writeSequenceVideo(dir.path().string(), dir.file("seq.mp4"), options), Error);
  EXPECT_FALSE(std::filesystem::exists(dir.file("seq.mp4")));
  test::TempDir empty;
  EXPECT_THROW(writeSequenceVideo(empty.path().string(), empty.file("seq.mp4"), VideoOptions()), Error);
}

TEST(SequenceVideo, DrawsTheTracksOfAFile) {
  test::TempDir dir;
  writeSequence(dir.path().string());
  io::TracksWriter tracks(dir.file("tracks.txt"));
  for (int i = 0; i <= 10; ++i) tracks.append({7, TimeNs(i) * 100 * kNsPerMs, Vec2(10, 10)});
  tracks.close();
  VideoOptions options;
  options.fps = 10.0;
  options.tracks = dir.file("tracks.txt");
  const VideoSummary s = writeSequenceVideo(dir.path().string(), dir.file("t.mp4"), options);
  EXPECT_EQ(s.tracks_file, options.tracks);
  cv::VideoCapture in(dir.file("t.mp4"), cv::CAP_FFMPEG);
  cv::Mat f;
  ASSERT_TRUE(in.read(f));
  // The track's circle (radius 2·scale around (10, 10)) is coloured, the grey frame is not.
  const cv::Vec3b ring = f.at<cv::Vec3b>((10 * 2) + 4, (10 * 2));
  const int spread = std::max({ring[0], ring[1], ring[2]}) - std::min({ring[0], ring[1], ring[2]});
  EXPECT_GT(spread, 60);
}

}  // namespace
}  // namespace evio::experiments

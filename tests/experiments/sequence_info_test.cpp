#include "evio/experiments/sequence_info.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/tum.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

// A synthetic folder whose every number is known exactly:
// 1000 events at 1 kHz from t = 1 s (x = i % 50, y = i % 30) except a burst
// of 100 extra events inside one 10 ms window; 201 IMU samples at 200 Hz;
// 11 frames at 10 Hz (50x30); ground truth moving 1 cm per pose along x.
void writeSequence(const std::string& folder, bool with_h5) {
  EventArray ev;
  for (int i = 0; i < 1000; ++i) {
    const TimeNs t = kNsPerSecond + TimeNs(i) * kNsPerMs;
    ev.push_back(t, static_cast<std::uint16_t>(i % 50), static_cast<std::uint16_t>(i % 30), i % 2);
    if (i == 500)
      for (int k = 0; k < 100; ++k) ev.push_back(t + 1000 * (k + 1), 3, 4, true);
  }
  io::writeEventsText(folder + "/events.txt", ev);
  if (with_h5) io::writeEventsH5(folder + "/events.h5", ev);
  ImuSamples imu;
  for (int i = 0; i <= 200; ++i) imu.push_back({kNsPerSecond + TimeNs(i) * 5 * kNsPerMs, Vec3(0, 0, 9.81), Vec3::Zero()});
  io::writeImuText(folder + "/imu.txt", imu);
  io::ImageFolderWriter frames(folder);
  for (int i = 0; i <= 10; ++i) frames.append(kNsPerSecond + TimeNs(i) * 100 * kNsPerMs, cv::Mat(30, 50, CV_8UC1, cv::Scalar(i)));
  frames.close();
  Trajectory gt;
  for (int i = 0; i <= 100; ++i) gt.push_back({kNsPerSecond + TimeNs(i) * 10 * kNsPerMs, Pose(Quat::Identity(), Vec3(0.01 * i, 0, 0))});
  io::writeTum(folder + "/groundtruth.txt", gt);
}

TEST(SequenceInfo, CountsRatesAndMissingFilesAreExact) {
  for (bool with_h5 : {false, true}) {
    test::TempDir dir;
    const std::string folder = dir.path().string();
    writeSequence(folder, with_h5);
    const SequenceInfo info = inspectSequence(folder);
    EXPECT_EQ(info.width, 50);
    EXPECT_EQ(info.height, 30);
    EXPECT_EQ(info.resolution_source, "first frame");
    EXPECT_EQ(info.events.count, 1100u);
    EXPECT_EQ(info.events.t_first_ns, kNsPerSecond);
    EXPECT_EQ(info.events.t_last_ns, kNsPerSecond + 999 * kNsPerMs);
    // 10 regular events plus the burst of 100 in the window [1.500, 1.510) s.
    EXPECT_DOUBLE_EQ(info.peak_event_rate_hz, 110.0 / 0.010);
    EXPECT_EQ(info.imu.count, 201u);
    EXPECT_NEAR(info.imu.meanRateHz(), 200.0, 1e-9);
    EXPECT_EQ(info.frames.count, 11u);
    EXPECT_NEAR(info.frames.meanRateHz(), 10.0, 1e-9);
    EXPECT_EQ(info.groundtruth.count, 101u);
    EXPECT_NEAR(info.groundtruth_path_length_m, 1.0, 1e-12);
    EXPECT_NEAR(info.durationS(), 1.0, 1e-12);
    const std::vector<std::string> expected_missing =
        with_h5 ? std::vector<std::string>{"calib.txt", "sensors.yaml"}
                : std::vector<std::string>{"events.h5", "calib.txt", "sensors.yaml"};
    EXPECT_EQ(info.missing, expected_missing);
    EXPECT_NE(formatSequenceInfo(info).find("1100 events"), std::string::npos);
    EXPECT_NE(sequenceInfoJson(info).find("\"count\": 1100"), std::string::npos);
  }
}

TEST(SequenceInfo, ResolutionFromEventsWhenNothingElse) {
  test::TempDir dir;
  EventArray ev;
  ev.push_back(1, 239, 3, true);
  ev.push_back(2, 7, 179, false);
  io::writeEventsText(dir.file("events.txt"), ev);
  const SequenceInfo info = inspectSequence(dir.path().string());
  EXPECT_EQ(info.width, 240);
  EXPECT_EQ(info.height, 180);
  EXPECT_FALSE(info.imu.present);
}

TEST(SequenceInfo, MalformedFileIsAnErrorNamingIt) {
  test::TempDir dir;
  writeSequence(dir.path().string(), false);
  {
    std::FILE* f = std::fopen(dir.file("imu.txt").c_str(), "a");
    std::fputs("2.0 1 2 3\n", f);
    std::fclose(f);
  }
  try {
    inspectSequence(dir.path().string());
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("imu.txt:202"), std::string::npos) << e.what();
  }
  EXPECT_THROW(inspectSequence(dir.file("nothing")), Error);
}

}  // namespace
}  // namespace evio::experiments

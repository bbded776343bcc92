// Round trips and bad-input cases for the Event-Camera Dataset text formats
// (events.txt, imu.txt, images.txt) and TUM trajectories.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/text_scanner.h"
#include "evio/core/io/tum.h"
#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "temp_dir.h"

namespace evio {
namespace {

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

/// Runs `f`, expects evio::Error, and checks that the message contains each of `parts`.
template <class F>
void expectErrorMentions(F&& f, std::initializer_list<std::string> parts) {
  try {
    f();
    ADD_FAILURE() << "expected evio::Error";
  } catch (const Error& e) {
    const std::string msg = e.what();
    for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "'" << p << "' not in: " << msg;
  }
}

EventArray randomEvents(std::size_t n, std::uint64_t seed) {
  RandomStream rng(seed, "events");
  EventArray ev;
  TimeNs t = 1'234'567;
  for (std::size_t i = 0; i < n; ++i) {
    t += static_cast<TimeNs>(rng.uniformInt(3000));  // includes equal timestamps
    ev.push_back(t, static_cast<std::uint16_t>(rng.uniformInt(240)),
                 static_cast<std::uint16_t>(rng.uniformInt(180)), rng.bernoulli(0.5));
  }
  return ev;
}

TEST(SecondsParsing, ExactNanoseconds) {
  TimeNs t = 0;
  ASSERT_TRUE(io::parseSecondsToNs("12.345678901", &t));
  EXPECT_EQ(t, 12'345'678'901);
  ASSERT_TRUE(io::parseSecondsToNs("0.0000000015", &t));  // rounds half up
  EXPECT_EQ(t, 2);
  ASSERT_TRUE(io::parseSecondsToNs("-0.5", &t));
  EXPECT_EQ(t, -500'000'000);
  ASSERT_TRUE(io::parseSecondsToNs("7", &t));
  EXPECT_EQ(t, 7'000'000'000);
  ASSERT_TRUE(io::parseSecondsToNs("1.5e-3", &t));
  EXPECT_EQ(t, 1'500'000);
  ASSERT_TRUE(io::parseSecondsToNs(".25", &t));
  EXPECT_EQ(t, 250'000'000);
  for (const char* bad : {"", "-", ".", "abc", "1.2.3", "1x", "nan", "inf", "1e400", "99999999999999999999"})
    EXPECT_FALSE(io::parseSecondsToNs(bad, &t)) << bad;
  std::string s;
  io::appendSeconds(s, -1);
  EXPECT_EQ(s, "-0.000000001");
  s.clear();
  io::appendSeconds(s, 12'345'678'901);
  EXPECT_EQ(s, "12.345678901");
}

TEST(EventsTxt, RoundTripIsExact) {
  test::TempDir dir;
  const EventArray ev = randomEvents(50'000, 1);
  io::writeEventsText(dir.file("events.txt"), ev);
  EXPECT_EQ(io::readEventsText(dir.file("events.txt"), io::SensorSize{240, 180}), ev);
}

TEST(EventsTxt, StreamingInChunksEqualsWhole) {
  test::TempDir dir;
  const EventArray ev = randomEvents(10'007, 2);
  {
    io::EventTextWriter w(dir.file("events.txt"));
    EventArray part;
    for (std::size_t i = 0; i < ev.size(); i += 1000) {
      part = ev;
      part.keepRange(i, i + 1000);
      w.append(part);
    }
    w.close();
  }
  io::EventTextReader r(dir.file("events.txt"));
  EventArray all, chunk;
  std::size_t chunks = 0;
  while (true) {
    chunk.clear();
    if (!r.next(chunk, 999)) break;
    EXPECT_LE(chunk.size(), 999u);
    all.append(chunk);
    ++chunks;
  }
  EXPECT_EQ(chunks, 11u);
  EXPECT_EQ(all, ev);
}

TEST(EventsTxt, AcceptsDatasetQuirks) {
  test::TempDir dir;
  // CRLF, tabs, a comment, a blank line, no final newline, polarity -1.
  writeText(dir.file("e.txt"), "# t x y p\r\n0.5 1 2 1\r\n\n0.5\t3\t4\t0\n0.6 5 6 -1");
  const EventArray ev = io::readEventsText(dir.file("e.txt"));
  ASSERT_EQ(ev.size(), 3u);
  EXPECT_EQ(ev[1], (Event{500'000'000, 3, 4, false}));
  EXPECT_EQ(ev[2], (Event{600'000'000, 5, 6, false}));
}

TEST(EventsTxt, BadInputNamesFileLineAndColumn) {
  test::TempDir dir;
  const std::string f = dir.file("events.txt");
  auto read = [&] { io::readEventsText(f, io::SensorSize{240, 180}); };
  writeText(f, "0.1 1 2 1\n0.2 1 2\n");
  expectErrorMentions(read, {f + ":2", "expected 4 columns"});
  writeText(f, "0.1 1 2 1 7\n");
  expectErrorMentions(read, {f + ":1", "expected 4 columns"});
  writeText(f, "0.1 1 2 1\nnan 1 2 1\n");
  expectErrorMentions(read, {f + ":2", "t:"});
  writeText(f, "0.1 1 2 1\ninf 1 2 1\n");
  expectErrorMentions(read, {f + ":2", "t:"});
  writeText(f, "0.2 1 2 1\n0.1 1 2 1\n");
  expectErrorMentions(read, {f + ":2", "decreases"});
  writeText(f, "0.1 240 2 1\n");
  expectErrorMentions(read, {f + ":1", "outside"});
  writeText(f, "0.1 1 180 1\n");
  expectErrorMentions(read, {f + ":1", "outside"});
  writeText(f, "0.1 -1 2 1\n");
  expectErrorMentions(read, {f + ":1", "x:"});
  writeText(f, "0.1 1.5 2 1\n");
  expectErrorMentions(read, {f + ":1", "x:"});
  writeText(f, "0.1 1 2 2\n");
  expectErrorMentions(read, {f + ":1", "p:", "polarity"});
  writeText(f, "0.1 1 2 1\n0.2 1 2 1\n0.3 1 2");  // truncated last line
  expectErrorMentions(read, {f + ":3", "expected 4 columns"});
  expectErrorMentions([&] { io::readEventsText(dir.file("missing.txt")); }, {"missing.txt", "cannot open"});
}

TEST(EventsTxt, WriterRejectsBackwardsTimeAndLeavesNoFile) {
  test::TempDir dir;
  EventArray ev;
  ev.push_back(10, 1, 1, true);
  ev.push_back(5, 1, 1, true);
  {
    io::EventTextWriter w(dir.file("events.txt"));
    EXPECT_THROW(w.append(ev), Error);
  }
  EXPECT_TRUE(std::filesystem::is_empty(dir.path()));
}

TEST(ImuTxt, RoundTripIsExact) {
  test::TempDir dir;
  RandomStream rng(4, "imu");
  ImuSamples samples;
  for (int i = 0; i < 2000; ++i) {
    ImuSample s;
    s.t_ns = 1'000'000'000 + TimeNs(i) * 1'000'000;
    s.acc_B = Vec3(rng.normal(0, 3), rng.normal(0, 3), rng.normal(9.81, 3));
    s.gyro_B = Vec3(rng.normal(), rng.normal(), rng.normal()) * 1e-3;
    samples.push_back(s);
  }
  io::writeImuText(dir.file("imu.txt"), samples);
  EXPECT_EQ(io::readImuText(dir.file("imu.txt")), samples);
}

TEST(ImuTxt, BadInput) {
  test::TempDir dir;
  const std::string f = dir.file("imu.txt");
  auto read = [&] { io::readImuText(f); };
  writeText(f, "0.1 0 0 9.8 0 0 0\n0.1 0 0 9.8 0 0 0\n");
  expectErrorMentions(read, {f + ":2", "increase strictly"});
  writeText(f, "0.1 0 0 9.8 0 0\n");
  expectErrorMentions(read, {f + ":1", "expected 7 columns"});
  writeText(f, "0.1 0 0 9.8 0 nan 0\n");
  expectErrorMentions(read, {f + ":1", "gy:"});
  writeText(f, "0.1 0 0 9.8 0 0 1e999\n");
  expectErrorMentions(read, {f + ":1", "gz:"});
}

Trajectory randomTrajectory(int n, std::uint64_t seed) {
  RandomStream rng(seed, "tum");
  Trajectory traj;
  for (int i = 0; i < n; ++i) {
    const Vec3 phi(rng.normal(), rng.normal(), rng.normal());
    traj.push_back({TimeNs(i) * 5'000'000 + 3, Pose(so3::expQuat(phi), Vec3(rng.normal(), rng.normal(), rng.normal()))});
  }
  return traj;
}

TEST(Tum, RoundTripIsExact) {
  test::TempDir dir;
  const Trajectory traj = randomTrajectory(500, 5);
  io::writeTum(dir.file("traj.txt"), traj, {"t tx ty tz qx qy qz qw"});
  const Trajectory back = io::readTum(dir.file("traj.txt"));
  ASSERT_EQ(back.size(), traj.size());
  for (std::size_t i = 0; i < traj.size(); ++i) {
    EXPECT_EQ(back[i].t_ns, traj[i].t_ns);
    EXPECT_EQ(back[i].pose.translation(), traj[i].pose.translation());
    EXPECT_EQ(back[i].pose.quaternion().coeffs(), traj[i].pose.quaternion().coeffs());
  }
}

TEST(Tum, CovarianceVariantRoundTrip) {
  test::TempDir dir;
  RandomStream rng(6, "cov");
  std::vector<io::StampedPoseCovariance> poses;
  for (const auto& p : randomTrajectory(100, 7)) {
    io::StampedPoseCovariance c;
    c.t_ns = p.t_ns;
    c.pose = p.pose;
    Mat3 A, B;
    for (int k = 0; k < 9; ++k) {
      A(k / 3, k % 3) = rng.normal();
      B(k / 3, k % 3) = rng.normal();
    }
    // The file stores upper triangles: the matrices must be exactly symmetric.
    const Mat3 Po = A * A.transpose() * 1e-4, Pt = B * B.transpose();
    c.cov_orientation = 0.5 * (Po + Po.transpose());
    c.cov_position = 0.5 * (Pt + Pt.transpose());
    poses.push_back(c);
  }
  io::writeTumCovariance(dir.file("cov.txt"), poses);
  const auto back = io::readTumCovariance(dir.file("cov.txt"));
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(back[i].t_ns, poses[i].t_ns);
    EXPECT_EQ(back[i].pose.translation(), poses[i].pose.translation());
    EXPECT_EQ(back[i].cov_orientation, poses[i].cov_orientation);
    EXPECT_EQ(back[i].cov_position, poses[i].cov_position);
  }
}

TEST(Tum, BadInput) {
  test::TempDir dir;
  const std::string f = dir.file("gt.txt");
  auto read = [&] { io::readTum(f); };
  writeText(f, "0.1 0 0 0 0 0 0 2\n");
  expectErrorMentions(read, {f + ":1", "quaternion norm"});
  writeText(f, "0.1 0 0 0 0 0 0 1\n0.05 0 0 0 0 0 0 1\n");
  expectErrorMentions(read, {f + ":2", "increase strictly"});
  writeText(f, "0.1 0 0 0 0 0 1\n");
  expectErrorMentions(read, {f + ":1", "expected 8 columns"});
  writeText(f, "0.1 0 x 0 0 0 0 1\n");
  expectErrorMentions(read, {f + ":1", "ty:"});
  const std::string c = dir.file("cov.txt");
  // Negative variance on the position diagonal.
  writeText(c, "0.1 0 0 0 0 0 0 1 1 0 0 1 0 1 -1 0 0 1 0 1\n");
  expectErrorMentions([&] { io::readTumCovariance(c); }, {c + ":1", "Pt", "positive semi-definite"});
}

TEST(ImagesTxt, RoundTripAndValidation) {
  test::TempDir dir;
  const std::string folder = dir.path().string();
  std::vector<cv::Mat> frames;
  {
    io::ImageFolderWriter w(folder);
    for (int i = 0; i < 3; ++i) {
      cv::Mat img(18, 24, CV_8UC1);
      cv::randu(img, 0, 256);
      frames.push_back(img);
      w.append(TimeNs(i) * 40'000'000 + 7, img);
    }
    w.close();
  }
  const auto list = io::readImageList(folder);
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[1].t_ns, 40'000'007);
  EXPECT_EQ(list[2].relative_path, "images/frame_00000002.png");
  for (int i = 0; i < 3; ++i) {
    const cv::Mat back = io::readFrame(folder, list[static_cast<std::size_t>(i)], cv::Size(24, 18));
    EXPECT_EQ(cv::norm(back, frames[static_cast<std::size_t>(i)], cv::NORM_INF), 0.0);
  }
  expectErrorMentions([&] { io::readFrame(folder, list[0], cv::Size(240, 180)); }, {"frame_00000000.png", "sensor"});

  writeText(dir.file("images.txt"), "0.1 images/frame_00000000.png\n0.2 images/nothere.png\n");
  expectErrorMentions([&] { io::readImageList(folder); }, {"images.txt:2", "does not exist"});
  writeText(dir.file("images.txt"), "0.1 images/frame_00000000.png\n0.1 images/frame_00000001.png\n");
  expectErrorMentions([&] { io::readImageList(folder); }, {"images.txt:2", "increase"});
  writeText(dir.file("images/frame_00000001.png"), "not a png");
  io::ImageStamp broken{1, "images/frame_00000001.png"};
  expectErrorMentions([&] { io::readFrame(folder, broken); }, {"frame_00000001.png", "not a readable image"});
}

}  // namespace
}  // namespace evio

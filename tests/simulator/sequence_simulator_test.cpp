// evio simulate (sequence_simulator.h): byte-identical folders with 1 and 2
// threads, and a folder whose files agree with each other and with the
// scenario (counts, clocks, labels, frames, depth).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "evio/core/io/atomic_file.h"
#include "evio/core/io/event_labels_bin.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tum.h"
#include "evio/core/so3.h"
#include "evio/simulator/motion_field.h"
#include "evio/simulator/sequence_simulator.h"
#include "temp_dir.h"

namespace evio::simulator {
namespace {

namespace fs = std::filesystem;

/// A small, fast scenario: the Mars yard seen from above at 64 × 48 px,
/// 0.2 s of the circle, DAVIS-style frames, a range finder, noise on.
const char* kScenario = R"(
description: test
seed: 7
duration_s: 0.2
scene: scenes/presets/mars_yard.yaml
trajectory:
  preset: trajectories/presets/circle.yaml
  duration_s: 1
  center_m: [-8.45, 0, 1.0]
  frequency_start_hz: 0.3
  frequency_end_hz: 0.3
rig:
  event_camera:
    preset: simulator/presets/davis346.yaml
    width: 64
    height: 48
    intrinsics: [45, 45, 31.5, 23.5]
    T_B_E: [1, 0, 0, 0,  0, -1, 0, 0,  0, 0, -1, 0,  0, 0, 0, 1]
    event_camera: {leak_rate_hz: 5, shot_noise_rate_hz: 5, hot_pixel_fraction: 0.01}
  frame_camera: {rate_hz: 40, exposure_samples: 3, sensor: {auto_exposure_max_s: 0.02}}
  imu: {update_rate_hz: 500}
  range_finder: {enabled: true, rate_hz: 50, T_B_L: [1, 0, 0, 0,  0, -1, 0, 0,  0, 0, -1, 0,  0, 0, 0, 1]}
sampling: {min_rate_hz: 200, max_rate_hz: 2000}
output: {truth_tracks: 30, truth_track_border_px: 2}
)";

Scenario loadTestScenario(const std::vector<std::string>& overrides = {}) {
  return loadScenarioString(kScenario, "test.yaml", EVIO_SOURCE_DIR, overrides, EVIO_SOURCE_DIR);
}

/// Every regular file below `dir`, as paths relative to it, sorted.
std::vector<std::string> filesBelow(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out.push_back(fs::relative(e.path(), dir).string());
  std::sort(out.begin(), out.end());
  return out;
}

/// Whether every file below a and b (simulation_stats.yaml aside: wall-clock
/// times) has the same bytes, the lists of files equal.
void expectSameFiles(const test::TempDir& tmp, const std::string& a, const std::string& b) {
  const auto files = filesBelow(tmp.path() / a);
  ASSERT_EQ(files, filesBelow(tmp.path() / b));
  for (const auto& f : files) {
    if (f == "simulation_stats.yaml") continue;
    EXPECT_EQ(io::readFile(tmp.file(a + "/" + f)), io::readFile(tmp.file(b + "/" + f))) << f << " differs";
  }
}

TEST(SequenceSimulator, ByteIdenticalWithOneAndTwoThreads) {
  test::TempDir tmp;
  const auto a = simulateSequence(loadTestScenario({"threads=1"}), tmp.file("a"));
  const auto b = simulateSequence(loadTestScenario({"threads=2"}), tmp.file("b"));
  ASSERT_GT(a.events, 100u);
  EXPECT_EQ(a.events, b.events);
  EXPECT_EQ(a.renders, b.renders);
  const auto files = filesBelow(tmp.path() / "a");
  for (const char* expected :
       {"events.h5", "events.txt", "images.txt", "imu.txt", "groundtruth.txt", "calib.txt", "sensors.yaml",
        "scenario.yaml", "range.txt", "simulation_stats.yaml", "truth/imu_state.txt", "truth/event_labels.bin",
        "truth/depth.txt", "truth/track_points.txt", "truth/tracks.txt", "truth/tracks_occluded.txt",
        "truth/range.txt", "images/frame_00000000.png", "truth/depth/depth_00000000.exr"})
    EXPECT_TRUE(std::count(files.begin(), files.end(), expected)) << expected;
  expectSameFiles(tmp, "a", "b");
}

TEST(SequenceSimulator, TileScheduleIsByteIdenticalWithOneAndTwoThreadsAndKeepsFramesExact) {
  test::TempDir tmp;
  const auto a = simulateSequence(loadTestScenario({"threads=1", "sampling.schedule=tiles", "sampling.tile_px=8"}),
                                  tmp.file("a"));
  const auto b = simulateSequence(loadTestScenario({"threads=2", "sampling.schedule=tiles", "sampling.tile_px=8"}),
                                  tmp.file("b"));
  ASSERT_GT(a.events, 100u);
  EXPECT_EQ(a.schedule, "tiles");
  EXPECT_GT(a.tile_steps, 0u);  // the tile steps ran, and traced fewer tiles than whole renders would have
  EXPECT_LT(a.tiles_rendered, (a.renders + a.tile_steps) * a.tile_count);
  EXPECT_EQ(a.tile_count, 8u * 6u);
  EXPECT_EQ(a.tiles_rendered, b.tiles_rendered);
  expectSameFiles(tmp, "a", "b");
  // The stream written step by step up to each watermark is time-sorted,
  // inside the window, one label per event.
  const Scenario scenario = loadTestScenario();
  const EventArray ev = io::readEventsText(tmp.file("a/events.txt"), io::SensorSize{64, 48});
  ASSERT_EQ(ev.size(), a.events);
  for (std::size_t i = 1; i < ev.size(); ++i) ASSERT_LE(ev.t()[i - 1], ev.t()[i]) << i;
  EXPECT_GE(ev.t().front(), scenario.start_ns);
  EXPECT_LE(ev.t().back(), scenario.end_ns);
  EXPECT_EQ(io::readEventLabels(tmp.file("a/truth/event_labels.bin")).size(), a.events);
  // Frames and depth come from whole renders at the same times in either
  // schedule: the same bytes as the whole-frame schedule's.
  const auto w = simulateSequence(loadTestScenario({"threads=2"}), tmp.file("w"));
  EXPECT_EQ(w.schedule, "whole_frame");
  EXPECT_EQ(w.tile_steps, 0u);
  EXPECT_EQ(w.tiles_rendered, w.renders * w.tile_count);
  ASSERT_GT(a.frames, 5u);
  EXPECT_EQ(a.frames, w.frames);
  EXPECT_EQ(a.depth_maps, w.depth_maps);
  for (const auto& f : filesBelow(tmp.path() / "a")) {
    if (f.rfind("images", 0) == 0 || f.rfind("truth/depth", 0) == 0 || f == "imu.txt" || f == "groundtruth.txt" ||
        f.rfind("truth/track", 0) == 0) {
      EXPECT_EQ(io::readFile(tmp.file("a/" + f)), io::readFile(tmp.file("w/" + f))) << f << " differs";
    }
  }
}

TEST(SequenceSimulator, FilesAgreeWithEachOther) {
  test::TempDir tmp;
  const Scenario scenario = loadTestScenario();
  const auto stats = simulateSequence(scenario, tmp.file("s"));
  const std::string dir = tmp.file("s");

  // Events: h5 = txt, one label each, all inside the window and the sensor.
  const EventArray h5 = io::readEventsH5(dir + "/events.h5", 64, 48);
  const EventArray txt = io::readEventsText(dir + "/events.txt", io::SensorSize{64, 48});
  ASSERT_EQ(h5.size(), stats.events);
  ASSERT_EQ(txt.size(), stats.events);
  for (std::size_t i = 0; i < h5.size(); i += 97) {
    EXPECT_EQ(h5.t()[i], txt.t()[i] / 1000 * 1000);  // h5 keeps µs (floored)
    EXPECT_EQ(h5.x()[i], txt.x()[i]);
    EXPECT_EQ(h5.p()[i], txt.p()[i]);
  }
  EXPECT_GE(txt.t().front(), scenario.start_ns);
  EXPECT_LE(txt.t().back(), scenario.end_ns);
  const auto labels = io::readEventLabels(dir + "/truth/event_labels.bin");
  ASSERT_EQ(labels.size(), stats.events);
  std::array<std::size_t, 4> per_label{};
  for (auto l : labels) ++per_label[l];
  EXPECT_GT(per_label[0], 0u);  // signal
  EXPECT_GT(per_label[1] + per_label[2] + per_label[3], 0u);  // noise is on

  // Clocks: IMU at 500 Hz, ground truth at 200 Hz, range at 50 Hz over [0, 0.2] s.
  EXPECT_EQ(io::readImuText(dir + "/imu.txt").size(), 101u);
  EXPECT_EQ(io::readImuStateText(dir + "/truth/imu_state.txt").size(), 101u);
  const Trajectory gt = io::readTum(dir + "/groundtruth.txt");
  ASSERT_EQ(gt.size(), 41u);
  // groundtruth.txt is T_W_E = T_W_B · T_B_E.
  const Pose T_W_E = scenario.trajectory->evaluate(gt[10].t_ns).T_W_B * scenario.T_B_E();
  EXPECT_LT((gt[10].pose.translation() - T_W_E.translation()).norm(), 1e-12);
  EXPECT_LT(angleBetween(gt[10].pose.quaternion(), T_W_E.quaternion()), 1e-9);
  const auto range = io::readRangeText(dir + "/range.txt");
  ASSERT_EQ(range.size(), 11u);
  const auto true_range = io::readRangeText(dir + "/truth/range.txt");
  for (std::size_t i = 0; i < range.size(); ++i) {
    ASSERT_TRUE(true_range[i].valid);
    EXPECT_NEAR(range[i].range_m, true_range[i].range_m, 0.2);  // sigma 0.02 m
    EXPECT_NEAR(true_range[i].range_m, 1.0, 0.2);               // about 1 m over the sand
  }

  // Frames at 40 Hz: exposures start at 0, 25, ... ms; the last one ends inside 0.2 s.
  const auto frames = io::readImageList(dir);
  ASSERT_GE(frames.size(), 7u);
  ASSERT_LE(frames.size(), 8u);
  EXPECT_EQ(frames.size(), stats.frames);
  const cv::Mat frame = io::readFrame(dir, frames.back(), cv::Size(64, 48));
  double mean = 0.0;
  for (int y = 0; y < frame.rows; ++y)
    for (int x = 0; x < frame.cols; ++x) mean += frame.at<std::uint8_t>(y, x);
  mean /= 64.0 * 48.0;
  EXPECT_GT(mean, 40.0);   // metered and auto-exposed towards 0.5 · 255
  EXPECT_LT(mean, 215.0);
  // Depth at each frame stamp, about 1 m below the camera.
  EXPECT_EQ(stats.depth_maps, frames.size());
  const cv::Mat depth = io::readExrChannel(dir + "/truth/depth/depth_00000000.exr", "Z");
  ASSERT_EQ(depth.size(), cv::Size(64, 48));
  EXPECT_NEAR(depth.at<float>(24, 32), 1.0, 0.25);

  // sensors.yaml: event camera first, co-located frame camera second.
  const SensorRig rig = io::readSensorsYaml(dir + "/sensors.yaml");
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[0].role, CameraRole::kEvent);
  EXPECT_EQ(rig.cameras[1].role, CameraRole::kFrame);
  EXPECT_EQ(rig.cameras[1].parameters.at("co_located_with_cam0"), 1.0);
  EXPECT_EQ(rig.gravity_m_s2, 9.81);  // from the circle preset (Earth)
  EXPECT_TRUE(rig.range_finder.has_value());
}

TEST(SequenceSimulator, ResolvedScenarioReproducesTheFolder) {
  test::TempDir tmp;
  simulateSequence(loadTestScenario(), tmp.file("a"));
  const Scenario again = loadScenario(tmp.file("a/scenario.yaml"), {}, EVIO_SOURCE_DIR);
  simulateSequence(again, tmp.file("b"));
  for (const auto& f : filesBelow(tmp.path() / "a")) {
    if (f == "simulation_stats.yaml") continue;
    EXPECT_EQ(io::readFile(tmp.file("a/" + f)), io::readFile(tmp.file("b/" + f))) << f;
  }
}

TEST(SequenceSimulator, FlowAtFramesIsTheMotionFieldOfTheTrueVelocity) {
  test::TempDir tmp;
  const Scenario s = loadTestScenario({"output.flow_at_frames=true", "output.write_events_txt=false"});
  simulateSequence(s, tmp.file("s"));
  const auto stamps = io::readImageList(tmp.file("s"));
  ASSERT_GE(stamps.size(), 3u);
  const auto channels = io::readExr(tmp.file("s/truth/depth/depth_00000002.exr"));
  ASSERT_EQ(channels.size(), 3u);  // U, V, Z (sorted by name)
  EXPECT_EQ(channels[0].first, "U");
  EXPECT_EQ(channels[1].first, "V");
  EXPECT_EQ(channels[2].first, "Z");
  // The velocity of E at the frame stamp by central differences of its pose
  // (h = 10 µs), and the motion field of the stored depth (motion_field.h).
  const auto T_W_E = [&](TimeNs t) { return s.trajectory->evaluate(t).T_W_B * s.T_B_E(); };
  const TimeNs t = stamps[2].t_ns, h = 10'000;
  const Pose a = T_W_E(t - h), b = T_W_E(t + h), c = T_W_E(t);
  CameraVelocity v;
  v.v_C = c.rotation().transpose() * (b.translation() - a.translation()) / (2e-9 * h);
  v.omega_C = so3::log(Mat3(a.rotation().transpose() * b.rotation())) / (2e-9 * h);
  const cv::Mat expected = motionFieldFromDepth(s.eventCamera(), channels[2].second, v);
  double worst = 0.0, mean_speed = 0.0;
  for (int y = 0; y < 48; ++y)
    for (int x_px = 0; x_px < 64; ++x_px) {
      const cv::Vec2f e = expected.at<cv::Vec2f>(y, x_px);
      const Vec2 got(channels[0].second.at<float>(y, x_px), channels[1].second.at<float>(y, x_px));
      worst = std::max(worst, (got - Vec2(e[0], e[1])).norm() / (1.0 + Vec2(e[0], e[1]).norm()));
      mean_speed += Vec2(e[0], e[1]).norm() / (64.0 * 48.0);
    }
  EXPECT_LT(worst, 1e-3);         // relative: float images, O(h²) differences
  EXPECT_GT(mean_speed, 30.0);    // 1.4 m/s at 1 m with f = 45 px: about 64 px/s
  EXPECT_LT(mean_speed, 120.0);
}

TEST(SequenceSimulator, SeparateFrameCameraHasItsOwnResolution) {
  test::TempDir tmp;
  const auto stats = simulateSequence(
      loadTestScenario({"rig.frame_camera.co_located=false", "rig.frame_camera.width=40",
                        "rig.frame_camera.height=30", "rig.frame_camera.intrinsics=[30,30,19.5,14.5]",
                        "rig.frame_camera.T_B_F=[1,0,0,0.05, 0,-1,0,0, 0,0,-1,0, 0,0,0,1]",
                        "output.write_events_txt=false", "rig.range_finder.enabled=false"}),
      tmp.file("s"));
  EXPECT_GT(stats.frame_renders, 3 * stats.frames - 1);
  const auto frames = io::readImageList(tmp.file("s"));
  ASSERT_FALSE(frames.empty());
  EXPECT_EQ(io::readFrame(tmp.file("s"), frames[0]).size(), cv::Size(40, 30));
  EXPECT_FALSE(fs::exists(tmp.file("s/events.txt")));
  EXPECT_FALSE(fs::exists(tmp.file("s/range.txt")));
  const SensorRig rig = io::readSensorsYaml(tmp.file("s/sensors.yaml"));
  ASSERT_EQ(rig.cameras.size(), 2u);
  EXPECT_EQ(rig.cameras[1].camera.width(), 40);
  EXPECT_NEAR(rig.cameras[1].T_B_C.translation().x(), 0.05, 1e-15);
}

}  // namespace
}  // namespace evio::simulator

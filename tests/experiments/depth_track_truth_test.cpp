#include "evio/experiments/depth_track_truth.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/exr_file.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tum.h"
#include "evio/experiments/track_metrics.h"
#include "error_of.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

using io::TrackSample;

constexpr TimeNs kMs = 1'000'000;
constexpr double kSpeed = 1.0;    // the camera moves along +x of W at 1 m/s ...
constexpr double kApproach = 0.5; // ... and along +z at 0.5 m/s; W = E at t = 0
constexpr double kPlaneZ = 2.0;   // a plane at z = 2 m in W, facing the camera

/// A sequence folder: a camera translating at (kSpeed, 0, kApproach) in
/// front of the plane z = kPlaneZ (poses every 5 ms over 1 s); depth maps
/// every 50 ms of the constant depth kPlaneZ − kApproach · t, except that
/// from 0.45 s on an occluder at 1 m covers the columns x < 120.
class Sequence {
 public:
  explicit Sequence(const Camera& camera) : camera_(camera) {
    std::filesystem::create_directories(dir_.path() / "truth" / "depth");
    SensorRig rig;
    rig.cameras.push_back(CameraSensor{"cam0", CameraRole::kEvent, camera, Pose::identity(), {}});
    rig.cameras.push_back(CameraSensor{"frames", CameraRole::kFrame, camera, Pose::identity(), {}});
    rig.cameras.push_back(
        CameraSensor{"aside", CameraRole::kFrame, camera, Pose(Quat::Identity(), Vec3(0.1, 0, 0)), {}});
    rig.imu.accelerometer_noise_density = 0.0028;
    rig.imu.accelerometer_random_walk = 0.00086;
    rig.imu.gyroscope_noise_density = 0.00016;
    rig.imu.gyroscope_random_walk = 2.2e-05;
    rig.imu.update_rate = 1000.0;
    rig.gravity_m_s2 = 3.721;
    io::writeSensorsYaml(dir_.file("sensors.yaml"), rig);
    Trajectory gt;
    for (TimeNs t = 0; t <= 1000 * kMs; t += 5 * kMs) gt.push_back({t, poseAt(t)});
    io::writeTum(dir_.file("groundtruth.txt"), gt);
    std::string list = "# t depth/depth_XXXXXXXX.exr\n";
    for (int k = 0; k <= 20; ++k) {
      const TimeNs t = k * 50 * kMs;
      cv::Mat z(camera.height(), camera.width(), CV_32FC1, cv::Scalar(planeDepth(t)));
      if (t >= 450 * kMs) z.colRange(0, 120).setTo(1.0);
      const std::string name = "depth/depth_" + std::to_string(k) + ".exr";
      io::writeExr(dir_.file("truth/" + name), {{"Z", z}});
      list += std::to_string(nsToSeconds(t)) + " " + name + "\n";
    }
    io::writeFileAtomic(dir_.file("truth/depth.txt"), list);
  }

  static Pose poseAt(TimeNs t_ns) {
    return Pose(Quat::Identity(), Vec3(kSpeed * nsToSeconds(t_ns), 0, kApproach * nsToSeconds(t_ns)));
  }
  static double planeDepth(TimeNs t_ns) { return kPlaneZ - kApproach * nsToSeconds(t_ns); }

  /// The exact pixel track of the plane point seen at u0 at t0, sampled every 10 ms.
  std::vector<TrackSample> track(std::int64_t id, TimeNs t0, const Vec2& u0, int samples) const {
    Vec3 b;
    EXPECT_TRUE(camera_.unproject(u0, &b));
    const Vec3 p_W = poseAt(t0) * Vec3(b * (planeDepth(t0) / b.z()));
    std::vector<TrackSample> out;
    for (int i = 0; i < samples; ++i) {
      const TimeNs t = t0 + i * 10 * kMs;
      Vec2 uv;
      camera_.project(poseAt(t).inverse() * p_W, &uv);
      out.push_back({id, t, uv});
    }
    return out;
  }

  std::string folder() const { return dir_.path().string(); }
  std::string file(const std::string& name) const { return dir_.file(name); }

 private:
  test::TempDir dir_;
  Camera camera_;
};

PinholeCamera pinhole() { return PinholeCamera(240, 180, PinholeCamera::Params(200, 200, 120, 90)); }

RadTanCamera radtan() {
  RadTanCamera::Params p;
  p << 199.1, 198.8, 122.2, 90.7, -0.37, 0.15, -3e-04, -8e-04, 0;
  return RadTanCamera(240, 180, p);
}

class DepthTrackTruthCameras : public ::testing::TestWithParam<bool> {};

// A perfect track has zero error; one 2 px off after its start has 2 px.
// On the pinhole camera u(t) = cx + fx (X − v t) / (Z − w t) with the world
// point X = (u0 − cx) / fx · (Z − w t0) + v t0 on the plane Z.
TEST_P(DepthTrackTruthCameras, PerfectTrackHasNoErrorAndOffsetTrackTwoPixels) {
  const Camera camera = GetParam() ? Camera(radtan()) : Camera(pinhole());
  const Sequence seq(camera);
  const DepthTrackTruth truth = loadDepthTrackTruth(seq.folder(), "", DepthTruthOptions());
  const auto perfect = seq.track(1, 100 * kMs, Vec2(150.3, 60.7), 21);
  if (!GetParam()) {
    const double x = 30.3 / 200 * (kPlaneZ - kApproach * 0.1) + kSpeed * 0.1;
    EXPECT_NEAR(perfect.back().uv.x(), 120 + 200 * (x - kSpeed * 0.3) / (kPlaneZ - kApproach * 0.3), 1e-9);
  }
  const TrackTruth t = truth.truthOf(perfect);
  ASSERT_EQ(t.status, TrackTruthStatus::kOk);
  ASSERT_EQ(t.uv.size(), perfect.size());
  for (std::size_t k = 0; k < perfect.size(); ++k) EXPECT_LT((t.uv[k] - perfect[k].uv).norm(), 1e-6) << k;

  auto offset = seq.track(2, 100 * kMs, Vec2(100.0, 120.0), 21);
  for (std::size_t k = 1; k < offset.size(); ++k) offset[k].uv.y() += 2.0;
  const TrackTruth o = truth.truthOf(offset);
  ASSERT_EQ(o.uv.size(), offset.size());
  EXPECT_LT((o.uv[0] - offset[0].uv).norm(), 1e-6);  // the start is taken as exact
  for (std::size_t k = 1; k < offset.size(); ++k) EXPECT_NEAR((o.uv[k] - offset[k].uv).norm(), 2.0, 1e-6) << k;

  std::vector<TrackSample> both = perfect;
  both.insert(both.end(), offset.begin(), offset.end());
  TrackMetricsOptions mo;
  mo.age_bin_s = 0.1;
  const TrackMetrics m = evaluateTracks(both, truth, mo);
  EXPECT_EQ(m.mode, "depth");
  EXPECT_EQ(m.matched_tracks, 2u);
  EXPECT_EQ(m.unevaluable_tracks, 0u);
  EXPECT_EQ(m.ended_by_track, 2u);
  EXPECT_NEAR(m.mean_error_px, 2.0 * 20 / 42.0, 1e-6);
  EXPECT_NEAR(m.mean_feature_age_s, 0.2, 1e-9);

  // A track starting between depth stamps (25 ms from both) is scored when
  // the tolerance allows: its depth is found on the nearest map's surface.
  const auto between = seq.track(3, 125 * kMs, Vec2(60.5, 100.2), 11);
  EXPECT_EQ(truth.truthOf(between).status, TrackTruthStatus::kNoDepthFrame);
  DepthTruthOptions wide;
  wide.max_depth_time_offset_s = 0.03;
  const TrackTruth w = loadDepthTrackTruth(seq.folder(), "", wide).truthOf(between);
  ASSERT_EQ(w.uv.size(), between.size());
  for (std::size_t k = 0; k < between.size(); ++k) EXPECT_LT((w.uv[k] - between[k].uv).norm(), 1e-6) << k;
}

INSTANTIATE_TEST_SUITE_P(PinholeAndRadTan, DepthTrackTruthCameras, ::testing::Bool());

// The truth ends when the point is occluded (the occluder appears in the
// depth map of 0.45 s, nearest to samples from 0.43 s on) or leaves the image.
TEST(DepthTrackTruth, OcclusionAndLeavingTheImageEndTheTruth) {
  const Sequence seq(pinhole());
  const DepthTrackTruth truth = loadDepthTrackTruth(seq.folder(), "cam0", DepthTruthOptions());
  // At 0.45 s it is at u = 113.5, behind the occluder.
  const auto hidden = seq.track(1, 100 * kMs, Vec2(150, 90), 61);
  EXPECT_EQ(truth.truthOf(hidden).uv.size(), 33u);  // samples 0.10 … 0.42 s
  // u = 120 + 200 (−0.875 − t) / (2 − 0.5 t): inside (u ≥ −0.5) up to 0.2536 s.
  const auto leaving = seq.track(2, 100 * kMs, Vec2(20, 90), 41);
  EXPECT_EQ(truth.truthOf(leaving).uv.size(), 16u);  // samples 0.10 … 0.25 s

  std::vector<TrackSample> both = hidden;
  both.insert(both.end(), leaving.begin(), leaving.end());
  const TrackMetrics m = evaluateTracks(both, truth, TrackMetricsOptions());
  EXPECT_EQ(m.ended_by_truth, 2u);
  EXPECT_NEAR(m.mean_feature_age_s, 0.5 * (0.32 + 0.15), 1e-9);
  EXPECT_LT(m.mean_error_px, 1e-6);
}

// Tracks not starting at a depth stamp, on a depth edge or at the border
// have no truth and are counted as unevaluable.
TEST(DepthTrackTruth, TracksWithoutTruthAreUnevaluable) {
  const Sequence seq(pinhole());
  const DepthTrackTruth truth = loadDepthTrackTruth(seq.folder(), "frames", DepthTruthOptions());
  const auto between = seq.track(1, 125 * kMs, Vec2(150, 90), 5);       // 25 ms from the stamps
  const auto near = seq.track(2, 100 * kMs + kMs / 2, Vec2(150, 90), 5);  // 0.5 ms: within 1 ms
  // At 0.45 s the occluder's edge lies between columns 119 and 120.
  const std::vector<TrackSample> edge = {{3, 450 * kMs, Vec2(120.2, 90)}, {3, 460 * kMs, Vec2(119.2, 90)}};
  const std::vector<TrackSample> border = {{4, 100 * kMs, Vec2(0.2, 90)}, {4, 110 * kMs, Vec2(0.1, 90)}};
  EXPECT_EQ(truth.truthOf(between).status, TrackTruthStatus::kNoDepthFrame);
  EXPECT_EQ(truth.truthOf(near).status, TrackTruthStatus::kOk);
  EXPECT_EQ(truth.truthOf(edge).status, TrackTruthStatus::kDiscontinuity);
  EXPECT_EQ(truth.truthOf(border).status, TrackTruthStatus::kNoSurface);

  std::vector<TrackSample> all = between;
  for (const auto* t : {&near, &edge, &border}) all.insert(all.end(), t->begin(), t->end());
  const TrackMetrics m = evaluateTracks(all, truth, TrackMetricsOptions());
  EXPECT_EQ(m.estimated_tracks, 4u);
  EXPECT_EQ(m.matched_tracks, 1u);
  EXPECT_EQ(m.unevaluable_tracks, 3u);
  EXPECT_EQ(m.unevaluable_no_depth_frame, 1u);
  EXPECT_EQ(m.unevaluable_depth, 2u);
  const std::string json = trackMetricsJson(m);
  EXPECT_NE(json.find("\"mode\": \"depth\""), std::string::npos) << json;
  EXPECT_NE(json.find("\"unevaluable_tracks\": 3"), std::string::npos) << json;
}

using test::errorOf;

TEST(DepthTrackTruth, BadInputIsOneClearError) {
  const Sequence seq(pinhole());
  const auto track = seq.track(1, 100 * kMs, Vec2(150, 90), 3);
  // A depth map that is not an EXR file.
  io::writeFileAtomic(seq.file("truth/depth/depth_2.exr"), "not an exr");
  const DepthTrackTruth truth = loadDepthTrackTruth(seq.folder(), "", DepthTruthOptions());
  EXPECT_NE(errorOf([&] { evaluateTracks(track, truth, TrackMetricsOptions()); }).find("depth_2.exr"),
            std::string::npos);
  // A depth map of the wrong size.
  io::writeExr(seq.file("truth/depth/depth_2.exr"), {{"Z", cv::Mat(10, 10, CV_32FC1, cv::Scalar(2.0))}});
  const DepthTrackTruth truth2 = loadDepthTrackTruth(seq.folder(), "", DepthTruthOptions());
  EXPECT_NE(errorOf([&] { truth2.truthOf(track); }).find("10x10"), std::string::npos);
  // A camera elsewhere than the event camera.
  EXPECT_NE(errorOf([&] { loadDepthTrackTruth(seq.folder(), "aside", DepthTruthOptions()); }).find("co-located"),
            std::string::npos);
  // A malformed line of depth.txt names the file and line.
  io::writeFileAtomic(seq.file("truth/depth.txt"), "0.0 depth/depth_0.exr\n0.05\n");
  EXPECT_NE(errorOf([&] { loadDepthTrackTruth(seq.folder(), "", DepthTruthOptions()); }).find("depth.txt:2"),
            std::string::npos);
  DepthTruthOptions bad;
  bad.occlusion_tolerance = 0.0;
  EXPECT_NE(errorOf([&] { bad.validate(); }).find("occlusion_tolerance"), std::string::npos);
}

}  // namespace
}  // namespace evio::experiments

// Ground-truth feature tracks (truth_tracks.h): picking, occlusion, and the
// tracks of a simulated folder against projections computed here
// independently (own radial-tangential formula, poses from groundtruth.txt).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>

#include "evio/core/io/calib_txt.h"
#include "evio/core/io/track_points_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/io/tum.h"
#include "evio/simulator/sequence_simulator.h"
#include "evio/simulator/truth_tracks.h"
#include "temp_dir.h"

namespace evio::simulator {
namespace {

Camera pinhole(int w, int h) {
  VecX none(0);
  return Camera::create("pinhole", w, h, Vec4(100, 100, (w - 1) / 2.0, (h - 1) / 2.0), none);
}

TEST(TruthTracks, PicksGridPointsAtTheirDepth) {
  const Camera cam = pinhole(64, 48);
  cv::Mat depth(48, 64, CV_32FC1, cv::Scalar(2.0f));
  depth.at<float>(12, 16) = std::numeric_limits<float>::infinity();  // sky: skipped wherever it falls
  const Pose T_W_E(Quat(Eigen::AngleAxisd(0.3, Vec3::UnitX())), Vec3(1, 2, 3));
  const auto points = pickTrackPoints(cam, T_W_E, depth, 12, 4.0);
  ASSERT_GE(points.size(), 11u);
  ASSERT_LE(points.size(), 12u);
  std::set<std::pair<long, long>> pixels;
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_EQ(points[i].id, static_cast<std::int64_t>(i));
    const Vec3 p_E = T_W_E.inverse() * points[i].p_W;
    EXPECT_NEAR(p_E.z(), 2.0, 1e-12);  // z of the depth image
    Vec2 uv;
    ASSERT_TRUE(cam.project(p_E, &uv));
    // An integer pixel inside the border.
    EXPECT_NEAR(uv.x(), std::round(uv.x()), 1e-9);
    EXPECT_NEAR(uv.y(), std::round(uv.y()), 1e-9);
    EXPECT_GE(uv.x(), 4.0 - 1e-9);
    EXPECT_LE(uv.x(), 63 - 4.0 + 1e-9);
    pixels.insert({std::lround(uv.x()), std::lround(uv.y())});
  }
  EXPECT_EQ(pixels.size(), points.size());  // all distinct
}

TEST(TruthTracks, OcclusionNeedsASurfaceInFrontOfThePoint) {
  const Camera cam = pinhole(64, 48);
  const Pose T_W_E;  // identity: looking along +z of W
  const Vec3 p_W(0.1, -0.05, 2.0);
  const double dist = p_W.norm();
  const auto at = [](double d) { return [d](const Vec3&, const Vec3&) { return d; }; };
  EXPECT_TRUE(observeTrackPoint(cam, T_W_E, p_W, at(dist)).visible());              // the point itself
  EXPECT_TRUE(observeTrackPoint(cam, T_W_E, p_W, at(dist * (1 - 0.5e-3))).visible());  // within tolerance
  const auto hidden = observeTrackPoint(cam, T_W_E, p_W, at(0.5 * dist));
  EXPECT_TRUE(hidden.projects);
  EXPECT_TRUE(hidden.occluded);
  EXPECT_NEAR(hidden.uv.x(), 100 * 0.1 / 2.0 + 31.5, 1e-12);
  EXPECT_FALSE(observeTrackPoint(cam, T_W_E, Vec3(0, 0, -2), at(dist)).projects);  // behind
  EXPECT_FALSE(observeTrackPoint(cam, T_W_E, Vec3(5, 0, 2), at(dist)).projects);   // outside the image
}

/// Projection through calib.txt's radial-tangential model, written out here:
///   x = X/Z, y = Y/Z, r² = x² + y², d = 1 + k1 r² + k2 r⁴ + k3 r⁶,
///   x' = x d + 2 p1 x y + p2 (r² + 2x²),  y' = y d + p1 (r² + 2y²) + 2 p2 x y,
///   u = fx x' + cx,  v = fy y' + cy.
Vec2 radtan(const io::CalibTxt& c, const Vec3& p) {
  const double x = p.x() / p.z(), y = p.y() / p.z(), r2 = x * x + y * y;
  const double k1 = c.distortion[0], k2 = c.distortion[1], p1 = c.distortion[2], p2 = c.distortion[3],
               k3 = c.distortion[4];
  const double d = 1 + k1 * r2 + k2 * r2 * r2 + k3 * r2 * r2 * r2;
  const double xd = x * d + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * d + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return Vec2(c.intrinsics[0] * xd + c.intrinsics[2], c.intrinsics[1] * yd + c.intrinsics[3]);
}

TEST(TruthTracks, MatchProjectionsComputedIndependently) {
  // The poster seen by a DAVIS240C with strong radial distortion, 6-DOF motion:
  // a plane facing the camera, so every projected sample is visible.
  const char* text = R"(
duration_s: 0.3
start_s: 40
scene: scenes/presets/ec_poster.yaml
trajectory: {preset: trajectories/presets/six_dof.yaml, center_m: [0, -1.0, 1.5], heading_deg: 90}
rig:
  event_camera:
    preset: simulator/presets/davis240c.yaml
    width: 120
    height: 90
    intrinsics: [100, 100, 66, 55]
    model: radtan
    distortion: [-0.37, 0.15, -0.0003, -0.0008, 0.0]
    T_B_E: [0, 0, 1, 0,  -1, 0, 0, 0,  0, -1, 0, 0,  0, 0, 0, 1]
  frame_camera: {enabled: false}
sampling: {min_rate_hz: 100, max_rate_hz: 300}
output: {truth_tracks: 40, write_events_txt: false}
)";
  test::TempDir tmp;
  const Scenario s = loadScenarioString(text, "tracks.yaml", EVIO_SOURCE_DIR, {}, EVIO_SOURCE_DIR);
  const std::string dir = tmp.file("s");
  const auto stats = simulateSequence(s, dir);
  ASSERT_EQ(stats.truth_tracks, 40u);

  const io::CalibTxt calib = io::readCalibTxt(dir + "/calib.txt");
  ASSERT_EQ(calib.distortion.size(), 5);
  std::map<TimeNs, Pose> poses;
  for (const auto& p : io::readTum(dir + "/groundtruth.txt")) poses[p.t_ns] = p.pose;
  const auto points = io::readTrackPoints(dir + "/truth/track_points.txt");
  ASSERT_EQ(points.size(), 40u);
  const auto tracks = io::readTracksText(dir + "/truth/tracks.txt");
  ASSERT_EQ(tracks.size(), stats.track_samples);

  double worst = 0.0;
  std::set<std::pair<std::int64_t, TimeNs>> listed;
  for (const auto& t : tracks) {
    ASSERT_TRUE(poses.count(t.t_ns)) << "track sample at a time without a ground-truth pose";
    const Pose& T_W_E = poses.at(t.t_ns);
    const Vec3 p_E = T_W_E.rotation().transpose() * (points[static_cast<std::size_t>(t.id)].p_W - T_W_E.translation());
    ASSERT_GT(p_E.z(), 0.0);
    worst = std::max(worst, (radtan(calib, p_E) - t.uv).norm());
    listed.insert({t.id, t.t_ns});
  }
  EXPECT_LT(worst, 1e-6) << "px";

  // Completeness: every (point, stamp) well inside the image is listed
  // (nothing stands between the camera and the poster).
  int expected = 0;
  for (const auto& [t, T_W_E] : poses)
    for (const auto& p : points) {
      const Vec3 p_E = T_W_E.rotation().transpose() * (p.p_W - T_W_E.translation());
      if (p_E.z() <= 0.0) continue;
      const Vec2 uv = radtan(calib, p_E);
      if (uv.x() < 1 || uv.y() < 1 || uv.x() > 118 || uv.y() > 88) continue;
      ++expected;
      EXPECT_TRUE(listed.count({p.id, t})) << "point " << p.id << " at " << t;
    }
  EXPECT_GT(expected, 40 * 20);  // most points stay in view over the 61 stamps
  EXPECT_TRUE(io::readTracksText(dir + "/truth/tracks_occluded.txt").empty());
}

}  // namespace
}  // namespace evio::simulator

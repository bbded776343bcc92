#include "evio/estimator/frontend/eklt_tracker.h"

#include <gtest/gtest.h>

#include <cmath>

#include "evio/core/camera/pinhole_camera.h"
#include "evio/estimator/frontend/feature_detection.h"
#include "support/synthetic_events.h"

namespace evio::estimator {
namespace {

using test::BlobTexture;
using test::RigidMotion;

constexpr int kWidth = 120;
constexpr int kHeight = 100;
constexpr double kContrast = 0.01;

Camera testCamera() { return Camera::create("pinhole", kWidth, kHeight, Vec4(100, 100, 59.5, 49.5), VecX()); }

/// The Harris corner of the frame at t = 0 nearest to `target`.
Vec2 nearestCorner(const BlobTexture& tex, const RigidMotion& m, const Vec2& target) {
  const cv::Mat image8 = test::render8(tex, m, 0.0, kWidth, kHeight);
  HarrisSettings hs;
  hs.max_corners = 200;
  hs.quality_level = 0.01;
  const std::vector<Vec2> corners = detectHarris(image8, {}, hs);
  EXPECT_FALSE(corners.empty());
  Vec2 best = target;
  for (const Vec2& c : corners)
    if ((c - target).norm() < (best - target).norm() || best == target) best = c;
  return best;
}

test::Roi roiAround(const std::vector<Vec2>& path, int margin) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (const Vec2& p : path) {
    x0 = std::min(x0, p.x());
    y0 = std::min(y0, p.y());
    x1 = std::max(x1, p.x());
    y1 = std::max(y1, p.y());
  }
  return test::Roi{std::max(0, static_cast<int>(x0) - margin), std::max(0, static_cast<int>(y0) - margin),
                   std::min(kWidth, static_cast<int>(x1) + margin + 1),
                   std::min(kHeight, static_cast<int>(y1) + margin + 1)};
}

struct TrackRun {
  TrackPoints points;
  std::optional<EkltTracker::FeatureState> final_state;
};

TrackRun runSingleFeature(const EkltOptions& options, const BlobTexture& tex, const RigidMotion& m, const Vec2& x0,
                          double duration_s, double initial_flow_angle) {
  std::vector<Vec2> path;
  for (int k = 0; k <= 20; ++k) path.push_back(m.forward(x0, duration_s * k / 20.0));
  const EventArray events = test::generateEvents(tex, m, roiAround(path, 13), 0.0, duration_s, 1e-3, kContrast);
  EkltTracker tracker(options, testCamera());
  const FeatureId id = tracker.addFeature(test::renderLog(tex, m, 0.0, kWidth, kHeight), x0, x0, 0,
                                          initial_flow_angle);
  tracker.addEvents(events);
  TrackRun run;
  tracker.drainTrackPoints(run.points);
  run.final_state = tracker.feature(id);
  return run;
}

TEST(EkltTracker, ConstantFlowRecoversDirectionAndDisplacement) {
  const BlobTexture tex = BlobTexture::random(3, kWidth, kHeight, 400);
  const double angle = 30.0 * M_PI / 180.0;
  RigidMotion m;
  m.velocity_px_s = 20.0 * Vec2(std::cos(angle), std::sin(angle));
  const Vec2 x0 = nearestCorner(tex, m, Vec2(40, 30));
  EkltOptions options;
  options.batch_contrast_threshold = kContrast;
  options.batch_max_events = 5000;
  if (const char* s = std::getenv("EKLT_SOLVER")) options.solver = s;
  const TrackRun run = runSingleFeature(options, tex, m, x0, 1.0, angle + 0.5);  // 29° off
  ASSERT_TRUE(run.final_state.has_value());
  ASSERT_GT(run.points.size(), 20u);
  double max_err = 0.0, sum_err = 0.0;
  int n = 0;
  for (const TrackPoint& p : run.points) {
    const Vec2 truth = m.forward(x0, nsToSeconds(p.t_ns));
    const double err = (p.uv - truth).norm();
    if (nsToSeconds(p.t_ns) > 0.1) {  // after the flow angle has converged
      max_err = std::max(max_err, err);
      sum_err += err;
      ++n;
    }
  }
  std::printf("points %zu max %.4f mean %.4f angle %.3f deg batch %d\n", run.points.size(), max_err, sum_err / n,
              run.final_state->flow_angle_rad * 180 / M_PI, run.final_state->batch_size);
  EXPECT_NEAR(run.final_state->flow_angle_rad, angle, 2.0 * M_PI / 180.0);
  EXPECT_LT(max_err, 0.1);
  const Vec2 truth_end = m.forward(x0, nsToSeconds(run.points.back().t_ns));
  EXPECT_LT((run.points.back().uv - truth_end).norm(), 0.1);
}

}  // namespace
}  // namespace evio::estimator

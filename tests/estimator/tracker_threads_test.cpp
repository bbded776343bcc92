// EKLT and HASTE with their features tracked in parallel (`threads`): the
// track points must be the same bits, in the same order, for any number of
// threads, and EKLT's single-thread output is pinned by a hash so that a
// change of the tracker's arithmetic (a faster evaluation, another summation
// order) cannot pass unnoticed.
#include "evio/estimator/frontend/eklt_tracker.h"
#include "evio/estimator/frontend/haste_tracker.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <vector>

#include "evio/core/camera/pinhole_camera.h"
#include "synthetic_events.h"

namespace evio::estimator {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 120;
constexpr double kContrast = 0.05;

/// 1 s of a blob texture turning about the image centre and drifting across
/// it, frames every 50 ms: up to 24 features of 30 slots with re-detection,
/// so that features are lost (at the border), slots are re-used and several
/// features share pixels and events. Generated once.
struct Scene {
  static constexpr double kDurationS = 1.0;
  static constexpr double kFrameDtS = 0.05;
  EventArray events;
  std::vector<cv::Mat> frames;

  static const Scene& get() {
    static const Scene scene = [] {
      const test::BlobTexture tex = test::BlobTexture::random(23, kWidth, kHeight, 500);
      test::RigidMotion m;
      m.velocity_px_s = Vec2(-60.0, 20.0);
      m.omega_rad_s = 0.5;
      m.centre = Vec2(0.5 * kWidth, 0.5 * kHeight);
      Scene s;
      s.events = test::generateEvents(tex, m, test::Roi{0, 0, kWidth, kHeight}, 0.0, kDurationS, 1e-3, kContrast);
      for (int f = 0; f * kFrameDtS <= kDurationS + 1e-9; ++f)
        s.frames.push_back(test::render8(tex, m, f * kFrameDtS, kWidth, kHeight));
      return s;
    }();
    return scene;
  }
};

/// Feeds the scene to `tracker` (EkltTracker or HasteTracker) and returns its points.
template <class Tracker>
TrackPoints feedScene(Tracker& tracker) {
  const Scene& scene = Scene::get();
  std::size_t next = 0;
  for (std::size_t f = 0; f < scene.frames.size(); ++f) {
    const TimeNs t_frame = secondsToNs(static_cast<double>(f) * Scene::kFrameDtS);
    const std::size_t end = scene.events.lowerBound(t_frame);
    // Chunks of 700 events, as the pipeline hands them between IMU samples.
    for (std::size_t b = next; b < end; b += 700) tracker.addEvents(scene.events, b, std::min(end, b + 700));
    next = end;
    tracker.addFrame(t_frame, scene.frames[f]);
  }
  TrackPoints points;
  tracker.drainTrackPoints(points);
  return points;
}

/// The scene's outputs input by input: one list of points per event chunk
/// and per frame. With `chunks_per_segment` > 0 the chunks between two frames
/// go to addEventChunks in segments of that many chunks (the pipeline's
/// FrontendStage), else one by one through addEvents.
template <class Tracker>
std::vector<TrackPoints> feedSceneByInput(Tracker& tracker, std::size_t chunks_per_segment) {
  const Scene& scene = Scene::get();
  std::vector<TrackPoints> outputs;
  std::size_t next = 0;
  for (std::size_t f = 0; f < scene.frames.size(); ++f) {
    const TimeNs t_frame = secondsToNs(static_cast<double>(f) * Scene::kFrameDtS);
    const std::size_t end = scene.events.lowerBound(t_frame);
    std::vector<std::size_t> chunk_ends;
    for (std::size_t b = next; b < end; b += 700) chunk_ends.push_back(std::min(end, b + 700));
    if (chunks_per_segment == 0) {
      std::size_t b = next;
      for (const std::size_t e : chunk_ends) {
        tracker.addEvents(scene.events, b, e);
        tracker.drainTrackPoints(outputs.emplace_back());
        b = e;
      }
    } else {
      for (std::size_t k = 0; k < chunk_ends.size(); k += chunks_per_segment) {
        // The segment's events in an array of their own, as FrontendStage holds them.
        const std::size_t first = k == 0 ? next : chunk_ends[k - 1];
        const std::size_t last = std::min(chunk_ends.size(), k + chunks_per_segment);
        EventArray segment;
        for (std::size_t i = first; i < chunk_ends[last - 1]; ++i)
          segment.push_back(scene.events.t()[i], scene.events.x()[i], scene.events.y()[i], scene.events.p()[i] != 0);
        std::vector<std::size_t> ends;
        for (std::size_t j = k; j < last; ++j) ends.push_back(chunk_ends[j] - first);
        TrackPoints points;
        std::vector<std::size_t> point_ends;
        tracker.addEventChunks(segment, ends, points, point_ends);
        EXPECT_EQ(point_ends.size(), ends.size());
        std::size_t b = 0;
        for (const std::size_t e : point_ends) {
          outputs.emplace_back(points.begin() + static_cast<std::ptrdiff_t>(b), points.begin() + static_cast<std::ptrdiff_t>(e));
          b = e;
        }
      }
    }
    next = end;
    tracker.addFrame(t_frame, scene.frames[f]);
    tracker.drainTrackPoints(outputs.emplace_back());
  }
  return outputs;
}

Camera sceneCamera() { return Camera::create("pinhole", kWidth, kHeight, Vec4(120, 120, 79.5, 59.5), VecX()); }

TrackPoints track(int threads, EkltTiming* timing = nullptr, bool single_precision = true) {
  EkltOptions options;
  options.single_precision = single_precision;
  options.batch_contrast_threshold = kContrast;
  options.max_features = 30;
  options.min_features = 24;
  options.harris_quality_level = 0.02;
  options.position_covariance = true;
  EkltTracker tracker(options, sceneCamera(), std::nullopt, threads);
  TrackPoints points = feedScene(tracker);
  if (timing) *timing = tracker.timing();
  return points;
}

TrackPoints trackHaste(int threads, HasteCounters* counters = nullptr) {
  HasteOptions options;
  options.max_features = 30;
  options.min_features = 24;
  options.harris_quality_level = 0.02;
  HasteTracker tracker(options, sceneCamera(), threads);
  TrackPoints points = feedScene(tracker);
  if (counters) *counters = tracker.counters();
  return points;
}

/// FNV-1a over every field of every point (positions and covariances as
/// their IEEE bits).
std::uint64_t hashPoints(const TrackPoints& points) {
  std::uint64_t h = 14695981039346656037ull;
  const auto mix = [&h](const void* data, std::size_t n) {
    const auto* bytes = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  };
  for (const TrackPoint& p : points) {
    mix(&p.feature_id, sizeof p.feature_id);
    mix(&p.t_ns, sizeof p.t_ns);
    mix(p.uv.data(), 2 * sizeof(double));
    mix(&p.quality, sizeof p.quality);
    const auto status = static_cast<int>(p.status);
    mix(&status, sizeof status);
    mix(p.cov_px.data(), 4 * sizeof(double));
  }
  return h;
}

void expectSamePoints(const TrackPoints& a, const TrackPoints& b, int threads) {
  ASSERT_EQ(a.size(), b.size()) << threads << " threads";
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].feature_id, b[i].feature_id) << "point " << i << ", " << threads << " threads";
    ASSERT_EQ(a[i].t_ns, b[i].t_ns) << "point " << i;
    ASSERT_EQ(std::memcmp(a[i].uv.data(), b[i].uv.data(), 2 * sizeof(double)), 0) << "point " << i;
    ASSERT_EQ(std::memcmp(&a[i].quality, &b[i].quality, sizeof(double)), 0) << "point " << i;
    ASSERT_EQ(a[i].status, b[i].status) << "point " << i;
    ASSERT_EQ(std::memcmp(a[i].cov_px.data(), b[i].cov_px.data(), 4 * sizeof(double)), 0) << "point " << i;
  }
}

TEST(EkltThreads, TrackPointsAreTheSameBitsForAnyThreadCount) {
  EkltTiming timing;
  const TrackPoints one = track(1, &timing);
  // The scene exercises what the partition must get right: many features,
  // many batches, features lost and slots re-used.
  int lost = 0, born = 0;
  for (const TrackPoint& p : one) {
    lost += p.status == TrackStatus::kLost;
    born += p.status == TrackStatus::kNew;
  }
  EXPECT_GT(timing.optimisations, 2000u);
  EXPECT_GE(lost, 5);
  EXPECT_GT(born, 30);  // more features than slots over the run: slots were re-used
  for (int threads : {2, 3, 7}) expectSamePoints(one, track(threads), threads);
}

TEST(HasteThreads, TrackPointsAreTheSameBitsForAnyThreadCount) {
  HasteCounters counters;
  const TrackPoints one = trackHaste(1, &counters);
  int lost = 0, born = 0;
  for (const TrackPoint& p : one) {
    lost += p.status == TrackStatus::kLost;
    born += p.status == TrackStatus::kNew;
  }
  EXPECT_GT(counters.jumps, 500u);
  EXPECT_GE(lost, 5);
  EXPECT_GT(born, 30);
  for (int threads : {2, 3, 7}) expectSamePoints(one, trackHaste(threads), threads);
}

EkltOptions sceneEkltOptions() {
  EkltOptions options;
  options.batch_contrast_threshold = kContrast;
  options.max_features = 30;
  options.min_features = 24;
  options.harris_quality_level = 0.02;
  options.position_covariance = true;
  return options;
}

TEST(EkltThreads, ChunksTrackedAsSegmentsGiveEachChunkItsOwnPointsForAnyThreadCount) {
  // The pipeline's segments (FrontendOptions::segment_s): many chunks in one
  // run of the threads must give every chunk exactly the points it gives
  // alone, whatever the segment's length (1, 3 or 100 chunks; 100 takes all
  // the chunks between two frames).
  EkltTracker reference(sceneEkltOptions(), sceneCamera(), std::nullopt, 1);
  const std::vector<TrackPoints> alone = feedSceneByInput(reference, 0);
  std::size_t points = 0, chunks_with_points = 0;
  for (const TrackPoints& o : alone) {
    points += o.size();
    chunks_with_points += !o.empty();
  }
  EXPECT_GT(points, 2000u);
  EXPECT_GT(chunks_with_points, 30u);
  for (const int threads : {1, 2, 3})
    for (const std::size_t per_segment : {std::size_t{1}, std::size_t{3}, std::size_t{100}}) {
      SCOPED_TRACE(std::to_string(threads) + " threads, " + std::to_string(per_segment) + " chunks per segment");
      EkltTracker tracker(sceneEkltOptions(), sceneCamera(), std::nullopt, threads);
      const std::vector<TrackPoints> segmented = feedSceneByInput(tracker, per_segment);
      ASSERT_EQ(segmented.size(), alone.size());
      for (std::size_t k = 0; k < alone.size(); ++k) expectSamePoints(alone[k], segmented[k], threads);
    }
}

TEST(HasteThreads, ChunksTrackedAsSegmentsGiveEachChunkItsOwnPointsForAnyThreadCount) {
  HasteOptions options;
  options.max_features = 30;
  options.min_features = 24;
  options.harris_quality_level = 0.02;
  HasteTracker reference(options, sceneCamera(), 1);
  const std::vector<TrackPoints> alone = feedSceneByInput(reference, 0);
  for (const int threads : {1, 2, 3}) {
    SCOPED_TRACE(std::to_string(threads) + " threads");
    HasteTracker tracker(options, sceneCamera(), threads);
    const std::vector<TrackPoints> segmented = feedSceneByInput(tracker, 100);
    ASSERT_EQ(segmented.size(), alone.size());
    for (std::size_t k = 0; k < alone.size(); ++k) expectSamePoints(alone[k], segmented[k], threads);
  }
}

// The single-thread output of this scene, pinned for both precisions of
// the optimiser's sums. Double precision: the one-pixel cost evaluation and
// the four-pixel AVX path give the same hash; single precision: the
// AVX-512, AVX and baseline lanes do (eklt_solver_test). Both last re-pinned
// when the optimiser's function tolerance went from 1e-4 to 1e-3
// (experiments/campaigns/eklt_tolerance.yaml: every cell's accuracy
// statistically unchanged, README "Real time (issue 22)"). A change that is meant to alter the numbers must
// say so, show the accuracy is kept and update the values here.
TEST(EkltThreads, SingleThreadOutputIsPinned) {
  for (const bool single : {true, false}) {
    const TrackPoints points = track(1, nullptr, single);
    const std::uint64_t pinned = single ? 0x17f84eee2c5254edull : 0x2affe5e06817e6dcull;
    EXPECT_EQ(hashPoints(points), pinned) << (single ? "single" : "double") << " precision: hash 0x" << std::hex
                                          << hashPoints(points) << ", " << std::dec << points.size() << " points";
  }
}

}  // namespace
}  // namespace evio::estimator

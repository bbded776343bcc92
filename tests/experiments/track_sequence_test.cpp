#include "evio/experiments/track_sequence.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <map>

#include "evio/core/io/calib_txt.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/estimator/frontend/eklt_cost.h"
#include "evio/experiments/track_metrics.h"
#include "synthetic_events.h"
#include "temp_dir.h"

namespace evio::experiments {
namespace {

constexpr int kWidth = 120;
constexpr int kHeight = 90;

/// A sequence folder (events.txt, images.txt + PNGs, calib.txt) of a texture
/// translating at 20 px/s for 0.3 s, frames at 20 Hz; and the exact track of
/// any point: truth(uv, t0, t) = forward(inverse(uv, t0), t).
struct SyntheticSequence {
  test::TempDir dir;
  test::BlobTexture tex = test::BlobTexture::random(41, kWidth, kHeight, 500);
  test::RigidMotion motion;
  SyntheticSequence() {
    motion.velocity_px_s = Vec2(16.0, 12.0);
    const std::string folder = dir.path().string();
    io::writeEventsText(folder + "/events.txt",
                        test::generateEvents(tex, motion, test::Roi{0, 0, kWidth, kHeight}, 0.0, 0.3, 1e-3, 0.02));
    io::ImageFolderWriter frames(folder);
    for (int f = 0; f <= 6; ++f) frames.append(secondsToNs(0.05 * f), test::render8(tex, motion, 0.05 * f, kWidth, kHeight));
    frames.close();
    io::writeCalibTxt(folder + "/calib.txt", io::CalibTxt{Vec4(100, 100, 59.5, 44.5), VecX()});
  }
  std::string folder() const { return dir.path().string(); }

  /// Ground truth for the first point of every estimated track.
  std::vector<io::TrackSample> truthFor(const std::vector<io::TrackSample>& est) const {
    std::map<std::int64_t, Vec2> origin;
    std::vector<io::TrackSample> truth;
    for (const auto& s : est)
      if (!origin.count(s.id)) origin[s.id] = motion.inverse(s.uv, nsToSeconds(s.t_ns));
    for (const auto& [id, X] : origin)
      for (int k = 0; k <= 300; ++k) truth.push_back({id, secondsToNs(k * 1e-3), motion.forward(X, k * 1e-3)});
    return truth;
  }
};

/// EKLT settings for SyntheticSequence's few sharp blobs: its contrast,
/// batches and detector.
void setEkltForTheBlobs(estimator::FrontendOptions& o) {
  o.eklt.batch_contrast_threshold = 0.02;
  o.eklt.batch_max_events = 5000;
  o.eklt.max_features = 10;
  o.eklt.min_features = 5;
  o.eklt.harris_quality_level = 0.05;
}

TEST(TrackSequence, EkltAndKltTrackASyntheticSequence) {
  SyntheticSequence seq;
  for (const char* tracker : {"eklt", "klt"}) {
    estimator::FrontendOptions o;
    o.tracker = tracker;
    setEkltForTheBlobs(o);
    const TrackSequenceResult r = trackSequence(seq.folder(), o);
    EXPECT_EQ(r.frames, 7u);
    EXPECT_GT(r.events, 10000u);
    EXPECT_GE(r.tracks, 5u) << tracker;
    TrackMetricsOptions mo;
    mo.match = "id";
    const TrackMetrics m = evaluateTracks(r.samples, seq.truthFor(r.samples), mo);
    EXPECT_EQ(m.matched_tracks, r.tracks);
    EXPECT_LT(m.mean_error_px, 0.3) << tracker;
    EXPECT_GT(m.mean_feature_age_s, 0.05) << tracker;
  }
}

// Each sample comes with what its tracker stated: EKLT its quality and a
// covariance no smaller than its floor, which with a reference cost grows as
// σ_min · cost / ref for the worse fits up to the cap (the reference here
// puts some floors at σ_min, some between it and the cap, some at the cap);
// KLT states none.
TEST(TrackSequence, EachSampleCarriesItsTrackersQualityAndCovariance) {
  SyntheticSequence seq;
  for (const double cost_ref : {0.0, 0.005}) {  // the fits here cost 0.002-0.014
    estimator::FrontendOptions o;
    setEkltForTheBlobs(o);
    o.eklt.position_sigma_cost_ref = cost_ref;
    const TrackSequenceResult r = trackSequence(seq.folder(), o);
    ASSERT_EQ(r.noise.size(), r.samples.size());
    const double sigma_min = o.eklt.position_sigma_min_px;
    const double sigma_max = o.eklt.position_sigma_max_px;
    int stated = 0, raised_between = 0;
    for (const io::TrackNoiseSample& n : r.noise) {
      EXPECT_GE(n.quality, 0.0);
      EXPECT_LE(n.quality, 1.0);
      if (n.cov_px.isZero()) continue;  // new and bootstrapped points: no batch, no covariance
      ++stated;
      const double floor = estimator::ekltSigmaFloor(2.0 * (1.0 - n.quality), sigma_min, sigma_max, cost_ref);
      const Eigen::SelfAdjointEigenSolver<Mat2> eig(n.cov_px);
      const double smallest = eig.eigenvalues().minCoeff();
      EXPECT_GE(smallest, floor * floor * (1.0 - 1e-9));
      EXPECT_LE(eig.eigenvalues().maxCoeff(), sigma_max * sigma_max * (1.0 + 1e-9));
      if (smallest > 1.01 * sigma_min * sigma_min && smallest < 0.99 * sigma_max * sigma_max) ++raised_between;
    }
    EXPECT_GT(stated, 20) << "EKLT states a covariance with each point it solves for (53 here)";
    // Without a reference every floor is σ_min (the curvature is far below
    // it on these sharp blobs); with one, some lie between σ_min and the cap.
    if (cost_ref > 0.0)
      EXPECT_GT(raised_between, 0);
    else
      EXPECT_EQ(raised_between, 0);
  }
  estimator::FrontendOptions klt;
  klt.tracker = "klt";
  const TrackSequenceResult r = trackSequence(seq.folder(), klt);
  ASSERT_EQ(r.noise.size(), r.samples.size());
  for (const io::TrackNoiseSample& n : r.noise) EXPECT_TRUE(n.cov_px.isZero());
}

// EKLT on frames reconstructed from events fused with the sensor frames
// (complementary filter): tracks stay within 1 px on average (0.59 px
// measured; the template comes from a reconstruction, not a sharp frame).
TEST(TrackSequence, ReconstructedFramesDriveEklt) {
  SyntheticSequence seq;
  estimator::FrontendOptions o;
  o.image_source = "reconstructed";
  o.reconstruction.contrast_threshold = 0.02;
  o.reconstruction.output_every_events = 20000;
  setEkltForTheBlobs(o);
  const TrackSequenceResult r = trackSequence(seq.folder(), o);
  EXPECT_GT(r.reconstructed_frames, 3u);
  EXPECT_GE(r.tracks, 3u);
  TrackMetricsOptions mo;
  mo.match = "id";
  const TrackMetrics m = evaluateTracks(r.samples, seq.truthFor(r.samples), mo);
  EXPECT_LT(m.mean_error_px, 1.0);
}

// The lag moved out of a point: τ times its velocity plus a along it. At
// (300, 400) px/s, |v| = 500 px/s, with τ = 2 ms and a = 0.5 px the point
// (3, 4) moves by (0.6, 0.8) + (0.3, 0.4) px. A still point stays.
TEST(TrackSequence, LagCompensationMovesAPointAlongItsMotion) {
  const estimator::TrackLag lag{0.5, 0.002};
  const Vec2 moved = lagCompensated(lag, Vec2(3, 4), Vec2(300, 400));
  EXPECT_NEAR(moved.x(), 3.9, 1e-12);
  EXPECT_NEAR(moved.y(), 5.2, 1e-12);
  EXPECT_EQ(lagCompensated(lag, Vec2(3, 4), Vec2::Zero()), Vec2(3, 4));
}

// --lag-compensated gives one point per tracked point, same ids and times;
// with the online estimate (from the first samples of these seven frames)
// points move, without it (track_lag.estimate off) none does. That they
// move toward the truth: tests/experiments/lag_compensated_tracks_test.py.
TEST(TrackSequence, LagCompensatedPointsMatchTheTrackedOnes) {
  SyntheticSequence seq;
  for (const bool estimate : {true, false}) {
    estimator::FrontendOptions o;
    setEkltForTheBlobs(o);
    o.track_lag.estimate = estimate;
    o.track_lag.min_samples = 1;  // seven frames: an estimate from the first samples
    const TrackSequenceResult r = trackSequence(seq.folder(), o, {}, LagCompensation{0.02});
    ASSERT_EQ(r.compensated.size(), r.samples.size());
    ASSERT_GT(r.samples.size(), 20u);
    std::size_t moved = 0;
    for (std::size_t i = 0; i < r.samples.size(); ++i) {
      EXPECT_EQ(r.compensated[i].id, r.samples[i].id);
      EXPECT_EQ(r.compensated[i].t_ns, r.samples[i].t_ns);
      if (r.compensated[i].uv != r.samples[i].uv) ++moved;
    }
    if (estimate)
      EXPECT_GT(moved, 0u) << "the lag estimated from the frames moves points";
    else
      EXPECT_EQ(moved, 0u);
  }
  estimator::FrontendOptions o;
  EXPECT_TRUE(trackSequence(seq.folder(), o).compensated.empty()) << "filled only when asked";
}

TEST(TrackSequence, MissingInputsAreErrors) {
  test::TempDir dir;
  EXPECT_THROW(trackSequence(dir.file("nope"), {}), Error);
  EXPECT_THROW(trackSequence(dir.path().string(), {}), Error);  // no frames, no events
}

TEST(TrackSequence, RunsOnTheRealSlicesAsTheyAre) {
  // tests/data/ecd (Event-Camera Dataset, Mueggler et al. 2017): an
  // events-only folder with calib.txt (no sensor size: taken from the
  // events, 240x180) and a frames-only folder. No hand-made sensors.yaml.
  const std::string root = std::string(EVIO_SOURCE_DIR) + "/tests/data/ecd/";
  estimator::FrontendOptions eklt;
  eklt.tracker = "eklt";
  eklt.image_source = "reconstructed";
  const TrackSequenceResult e = trackSequence(root + "shapes_rotation_events", eklt);
  EXPECT_EQ(e.events, 50879u);  // every line of events.txt
  EXPECT_EQ(e.frames, 0u);
  EXPECT_NE(e.camera_name.find("events (max x, y + 1)"), std::string::npos) << e.camera_name;
  EXPECT_GT(e.tracks, 0u);
  estimator::FrontendOptions klt;
  klt.tracker = "klt";
  const TrackSequenceResult k = trackSequence(root + "boxes_6dof_frames", klt);
  EXPECT_EQ(k.frames, 60u);
  EXPECT_EQ(k.events, 0u);
  EXPECT_GT(k.tracks, 0u);
  // EKLT on the frames-only folder still needs its events: one clear error.
  eklt.image_source = "frames";
  try {
    trackSequence(root + "boxes_6dof_frames", eklt);
    ADD_FAILURE() << "EKLT ran without events";
  } catch (const Error& err) {
    EXPECT_NE(std::string(err.what()).find("no events.h5 or events.txt"), std::string::npos) << err.what();
  }
}

}  // namespace
}  // namespace evio::experiments

// The gyroscope bias from the first tracks in the pipeline
// (pipeline/gyro_bias_window.h) on tiny sequence folders
// (support/tiny_sequence.h) whose simulated gyroscope has a known bias: the
// `tracks` method on exact ground-truth tracks with pixel noise; the same
// output with the backend on its own thread.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/tum.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "support/tiny_sequence.h"
#include "temp_dir.h"

namespace evio::estimator {
namespace {

const Vec3 kTrueBias(0.05, -0.04, 0.03);  // rad/s: 2.9, −2.3, 1.7 °/s

/// The backend on the tracks, started from the ground truth with zero bias
/// and the defaults' 6°/s, the bias from the first window_s of tracks.
PipelineOptions windowOptions(double window_s, double noise_px = 0.5) {
  PipelineOptions o = PipelineOptions::forMethod("tracks");
  o.init.mode = "groundtruth";
  o.init.gyro_bias_window_s = window_s;
  o.tracks.noise_px = noise_px;
  o.backend.sigma_img_px = 1.0;
  o.backend.slam_min_depth_m = 1.5;  // the landmarks are 2-5 m away
  return o;
}

/// duration_s of the tiny rig with the simulated gyroscope bias kTrueBias,
/// written to `dir`/seq; returns the folder.
std::string writeBiasedSequence(const test::TempDir& dir, const std::string& trajectory_preset = "six_dof.yaml",
                                double duration_s = 3.0) {
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = duration_s;
  so.gyro_bias_radps = kTrueBias;
  so.trajectory_preset = trajectory_preset;
  writeTinySequence(seq, so);
  return seq;
}

TEST(PipelineGyroBias, TheWindowFindsTheSimulatedBiasAndTheFilterStartsAtTheInitialTime) {
  // Exact tracks with 0.5 px of noise at 20 Hz of a cloud in front of the
  // camera: the estimate is inside its 99.9 % ellipsoid (χ²₃ < 16.3) and
  // within 0.2 °/s of the simulated bias (measured: 0.073 °/s; 0.023 °/s
  // without the noise, 0.195 °/s with 1 px). The filter starts at the
  // ground-truth time with the window replayed: the first pose is at the
  // initial time.
  test::TempDir dir;
  const std::string seq = writeBiasedSequence(dir), out = dir.file("out");
  const PipelineResult r = runPipeline(seq, windowOptions(1.0), out);
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  ASSERT_TRUE(r.gyro_bias.has_value());
  ASSERT_TRUE(r.gyro_bias->from_tracks);
  const Vec3 d = r.gyro_bias->b_g - kTrueBias;
  EXPECT_LT(d.dot(r.gyro_bias->covariance.inverse() * d), 16.3);
  EXPECT_LT(d.norm(), 0.2 * M_PI / 180.0);
  ASSERT_TRUE(r.initialization_t_ns.has_value());
  EXPECT_EQ(*r.initialization_t_ns, 0);
  const Trajectory est = io::readTum(out + "/trajectory.txt");
  ASSERT_FALSE(est.empty());
  EXPECT_LT(est.front().t_ns, secondsToNs(0.1));
  std::printf("bias from tracks: error %.3f deg/s, sigma %.3f %.3f %.3f deg/s, %d pairs, %d residuals\n",
              d.norm() * 180.0 / M_PI, std::sqrt(r.gyro_bias->covariance(0, 0)) * 180.0 / M_PI,
              std::sqrt(r.gyro_bias->covariance(1, 1)) * 180.0 / M_PI,
              std::sqrt(r.gyro_bias->covariance(2, 2)) * 180.0 / M_PI, r.gyro_bias->pairs, r.gyro_bias->residuals);
}

TEST(PipelineGyroBias, AWindowAtRestTakesTheBiasesFromTheMeanReadings) {
  // The flight preset's first 2 s on the ground: the window's IMU is at rest
  // (no 50 ms block's mean moves; the frames cannot tell, the tracks method
  // having none), so its mean rate gives the simulated 4.1 °/s bias to its
  // white noise, σ_g/√T (the tiny rig's σ_g = 2e-4 rad/s/√Hz, T = 1 s:
  // 0.0115 °/s; a whole still window carries no allowance), and the filter
  // starts with that covariance, not the prior's 6 °/s, at the window's
  // end. The spread test alone (init.gyro_bias_window_rest_prefix_s = 0)
  // gives the same. With the rest
  // test off the same window goes to the tracks (a camera at rest shows a
  // rotation error too: the tracks find the bias, and the filter keeps the
  // prior's σ, since it takes the tracks again).
  test::TempDir dir;
  const std::string seq = writeBiasedSequence(dir, "flight.yaml");
  const PipelineResult r = runPipeline(seq, windowOptions(1.0), dir.file("out"));
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  ASSERT_TRUE(r.gyro_bias.has_value());
  EXPECT_TRUE(r.gyro_bias->at_rest);
  EXPECT_FALSE(r.gyro_bias->from_tracks);
  EXPECT_NEAR(r.gyro_bias->rest_s, 1.0, 0.01);
  // The window at rest is the initialisation: the filter starts at its end.
  ASSERT_TRUE(r.initialization_t_ns.has_value());
  EXPECT_NEAR(nsToSeconds(*r.initialization_t_ns), 1.0, 0.01);
  const Vec3 d = r.gyro_bias->b_g - kTrueBias;
  const double sigma = std::sqrt(r.gyro_bias->covariance(0, 0));
  const double white = 2e-4 / std::sqrt(1.0);
  // The prior's 6 °/s shrinks the posterior below the measurement's σ by
  // (1 + σ²/σ_prior²)^(-1/2): 2e-6.
  EXPECT_NEAR(sigma, white, 0.01 * white);
  ASSERT_GT(r.gyro_bias->rest_image_features, 5);  // the tracks say still too
  EXPECT_LT(r.gyro_bias->rest_image_chi2, 16.27);
  EXPECT_LT(d.dot(r.gyro_bias->covariance.inverse() * d), 16.3);  // χ²₃ 99.9 %
  std::printf("bias at rest: error %.4f deg/s, sigma %.4f deg/s\n", d.norm() * 180.0 / M_PI, sigma * 180.0 / M_PI);
  PipelineOptions spread_only = windowOptions(1.0);
  spread_only.init.gyro_bias_window_rest_prefix_s = 0.0;
  const PipelineResult r_spread = runPipeline(seq, spread_only, dir.file("out_spread"));
  ASSERT_TRUE(r_spread.gyro_bias.has_value() && r_spread.gyro_bias->at_rest);
  EXPECT_NEAR(std::sqrt(r_spread.gyro_bias->covariance(0, 0)), white, 0.05 * white);
  // The accelerometer's bias (zero in the tiny rig) comes from the mean force,
  // inside its own 99.9 % ellipsoid, and the summary reports both biases.
  const Vec3& b_a = r.gyro_bias->rest_b_a;
  ASSERT_GT(r.gyro_bias->rest_b_a_covariance.determinant(), 0.0);
  EXPECT_LT(b_a.dot(r.gyro_bias->rest_b_a_covariance.inverse() * b_a), 16.3);
  const std::string summary = io::readFile(dir.file("out/summary.yaml"));
  EXPECT_NE(summary.find("b_a_mps2:"), std::string::npos);
  EXPECT_NE(summary.find("sigma_b_a_mps2:"), std::string::npos);

  PipelineOptions off = windowOptions(1.0);
  off.init.gyro_bias_window_rest = false;
  const PipelineResult r_off = runPipeline(seq, off, dir.file("out_off"));
  ASSERT_TRUE(r_off.gyro_bias.has_value());
  EXPECT_FALSE(r_off.gyro_bias->at_rest);
  EXPECT_TRUE(r_off.gyro_bias->from_tracks);
}

/// The first time, s, at which the flight preset's motion is plain to the
/// still-prefix test: acceleration above 0.16 m/s² or rate above 0.008
/// rad/s, twice the test's thresholds on a 50 ms block's mean (4 σ_b √(1 +
/// 1/k) ≤ 0.08 m/s² and 0.004 rad/s at the tiny rig's densities).
double flightPlainMotionS() {
  const auto traj = test::tinyTrajectory("flight.yaml");
  for (TimeNs t = traj->startTime(); t < traj->endTime(); t += secondsToNs(0.001)) {
    const TrajectoryState x = traj->evaluate(t);
    if (x.a_W.norm() > 0.16 || x.omega_B.norm() > 0.008) return nsToSeconds(t - traj->startTime());
  }
  return nsToSeconds(traj->endTime() - traj->startTime());
}

TEST(PipelineGyroBias, AWindowStillUntilItMovesTakesTheBiasesFromItsStillPrefix) {
  // The flight preset: 2 s on the ground, then the take-off, a C∞ smoothstep
  // whose force grows from zero. In a 3.5 s window the still prefix (blocks of
  // 50 ms whose means do not move, backend/still_prefix.h) ends between the
  // take-off (one block earlier on a false alarm) and one block after the
  // motion is plain (flightPlainMotionS). Its mean rate gives the simulated
  // 4.1 °/s bias inside the 99.9 % ellipsoid of the stated covariance (white
  // noise over the prefix plus the test's allowance for a drift it could not
  // see, 0.12 °/s per axis); the filter starts at the prefix's end.
  test::TempDir dir;
  const std::string seq = writeBiasedSequence(dir, "flight.yaml", 4.0);
  const double plain_s = flightPlainMotionS();
  ASSERT_LT(plain_s + 0.1, 3.5);  // inside the window
  const PipelineResult r = runPipeline(seq, windowOptions(3.5), dir.file("out"));
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  ASSERT_TRUE(r.gyro_bias.has_value());
  EXPECT_TRUE(r.gyro_bias->at_rest);
  EXPECT_TRUE(r.gyro_bias->rest_prefix);
  EXPECT_FALSE(r.gyro_bias->from_tracks);
  EXPECT_GE(r.gyro_bias->rest_s, 2.0 - 0.05);
  EXPECT_LE(r.gyro_bias->rest_s, plain_s + 0.05);
  ASSERT_TRUE(r.initialization_t_ns.has_value());
  EXPECT_NEAR(nsToSeconds(*r.initialization_t_ns), r.gyro_bias->rest_s, 0.002);
  const Vec3 d = r.gyro_bias->b_g - kTrueBias;
  EXPECT_LT(d.dot(r.gyro_bias->covariance.inverse() * d), 16.3);  // χ²₃ 99.9 %
  const double sigma = std::sqrt(r.gyro_bias->covariance(0, 0));
  EXPECT_LT(sigma, 0.15 * M_PI / 180.0);
  std::printf("still prefix %.3f s (motion plain at %.3f s): bias error %.4f deg/s, sigma %.4f deg/s\n",
              r.gyro_bias->rest_s, plain_s, d.norm() * 180.0 / M_PI, sigma * 180.0 / M_PI);
  const std::string summary = io::readFile(dir.file("out/summary.yaml"));
  EXPECT_NE(summary.find("rest_prefix: true"), std::string::npos);

  // With init.gyro_bias_window_rest_prefix_s = 0 the spread test alone
  // judges the whole window: the climb's spread fails it, and the window
  // goes to the tracks.
  PipelineOptions off = windowOptions(3.5);
  off.init.gyro_bias_window_rest_prefix_s = 0.0;
  const PipelineResult r_off = runPipeline(seq, off, dir.file("out_off"));
  ASSERT_TRUE(r_off.gyro_bias.has_value());
  EXPECT_FALSE(r_off.gyro_bias->rest_prefix);
  EXPECT_FALSE(r_off.gyro_bias->at_rest);
  EXPECT_TRUE(r_off.gyro_bias->from_tracks);
}

TEST(PipelineGyroBias, TracksOnceStartsFromTheWindowAndSkipsItsSets) {
  // init.gyro_bias_window_tracks_once: the same window estimate, and the
  // filter skips the window's second of measurement sets (it holds only the
  // window's IMU), then runs on the later ones.
  test::TempDir dir;
  const std::string seq = writeBiasedSequence(dir);
  const PipelineResult twice = runPipeline(seq, windowOptions(1.0), dir.file("twice"));
  PipelineOptions o = windowOptions(1.0);
  o.init.gyro_bias_window_tracks_once = true;
  const PipelineResult once = runPipeline(seq, o, dir.file("once"));
  ASSERT_TRUE(twice.status.ok()) << twice.status.cause;
  ASSERT_TRUE(once.status.ok()) << once.status.cause;
  ASSERT_TRUE(once.gyro_bias.has_value() && twice.gyro_bias.has_value());
  EXPECT_EQ(once.gyro_bias->b_g, twice.gyro_bias->b_g);
  EXPECT_GE(twice.counts.measurement_sets, once.counts.measurement_sets + 10);
  EXPECT_GT(once.counts.measurement_sets, 10u);
}

TEST(PipelineGyroBias, TheReplayStartsWithThePriorSigmaOrTheWindowsAsAsked) {
  // init.gyro_bias_window_sigma: the replay's filter starts with the prior's
  // bias block (6 °/s on each axis, uncorrelated) or with the window's
  // estimate's covariance, exactly; the summary states which σ it was told.
  test::TempDir dir;
  const std::string seq = writeBiasedSequence(dir);
  const PipelineResult prior = runPipeline(seq, windowOptions(1.0), dir.file("prior"));
  PipelineOptions o = windowOptions(1.0);
  o.init.gyro_bias_window_sigma = "window";
  const PipelineResult window = runPipeline(seq, o, dir.file("window"));
  ASSERT_TRUE(prior.status.ok()) << prior.status.cause;
  ASSERT_TRUE(window.status.ok()) << window.status.cause;
  ASSERT_TRUE(prior.gyro_bias.has_value() && window.gyro_bias.has_value());
  ASSERT_TRUE(window.gyro_bias->from_tracks);
  const double prior_sigma = 6.0 * (M_PI / 180.0), prior_var = prior_sigma * prior_sigma;
  EXPECT_EQ(prior.gyro_bias->filter_start_covariance, Mat3(Vec3::Constant(prior_var).asDiagonal()));
  EXPECT_EQ(window.gyro_bias->filter_start_covariance, window.gyro_bias->covariance);
  // The window's σ is far below the prior's here (0.5 px tracks).
  EXPECT_LT(window.gyro_bias->covariance.diagonal().maxCoeff(), 0.1 * prior_var);
  EXPECT_NE(io::readFile(dir.file("window/summary.yaml")).find("filter_start_sigma_degps:"), std::string::npos);
  // The same window estimate either way; the filter's run differs.
  EXPECT_EQ(window.gyro_bias->b_g, prior.gyro_bias->b_g);
  EXPECT_NE(io::readFile(dir.file("window/trajectory.txt")), io::readFile(dir.file("prior/trajectory.txt")));
}

TEST(PipelineGyroBias, AWindowLongerThanTheDataClosesAtTheEnd) {
  // A window of 10 s over 2 s of data: closed at the end of the data with
  // what it holds, the filter then runs over all of it.
  test::TempDir dir;
  const std::string seq = dir.file("seq"), out = dir.file("out");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  so.gyro_bias_radps = kTrueBias;
  writeTinySequence(seq, so);
  PipelineOptions o = windowOptions(10.0);
  o.init.gyro_bias_keyframe_s = 0.2;
  const PipelineResult r = runPipeline(seq, o, out);
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  ASSERT_TRUE(r.gyro_bias.has_value());
  EXPECT_TRUE(r.gyro_bias->from_tracks);
  EXPECT_GT(r.counts.poses, 10u);
  EXPECT_GT(r.counts.measurement_sets, 30u);
}

TEST(PipelineGyroBias, TheBackendOnItsOwnThreadWritesTheSameTrajectory) {
  // The window is held and replayed on the backend's side; with that side on
  // its own thread the estimate is byte-identical, also when the data end
  // inside the window (closed after the thread stopped).
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  so.gyro_bias_radps = kTrueBias;
  writeTinySequence(seq, so);
  for (const double window_s : {1.0, 10.0}) {
    PipelineOptions o = windowOptions(window_s);
    o.backend_thread = false;
    runPipeline(seq, o, dir.file("inline"));
    o.backend_thread = true;
    runPipeline(seq, o, dir.file("thread"));
    EXPECT_EQ(io::readFile(dir.file("inline") + "/trajectory.txt"), io::readFile(dir.file("thread") + "/trajectory.txt"))
        << "window " << window_s << " s";
  }
}

/// The message validate() throws, or "" when it does not.
std::string validationError(const InitOptions& o) {
  try {
    o.validate();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(PipelineGyroBias, TheWindowNeedsTheGroundTruthStartAndTwoPairs) {
  PipelineOptions o = windowOptions(1.0);
  EXPECT_EQ(validationError(o.init), "");
  o.init.mode = "static";
  EXPECT_NE(validationError(o.init).find("gyro_bias_window_s"), std::string::npos);
  o = windowOptions(1.0);
  o.init.gyro_bias_keyframe_s = 0.5;
  EXPECT_NE(validationError(o.init).find("gyro_bias_keyframe_s"), std::string::npos);
  o = windowOptions(1.0);
  o.init.gyro_bias_window_sigma = "posterior";
  EXPECT_NE(validationError(o.init).find("gyro_bias_window_sigma"), std::string::npos);
  // The still prefix: at least two blocks (or 0, off), and a positive block.
  o = windowOptions(1.0);
  o.init.gyro_bias_window_rest_prefix_s = 0.08;
  EXPECT_NE(validationError(o.init).find("gyro_bias_window_rest_prefix_s"), std::string::npos);
  o.init.gyro_bias_window_rest_prefix_s = -1.0;
  EXPECT_NE(validationError(o.init).find("gyro_bias_window_rest_prefix_s"), std::string::npos);
  o.init.gyro_bias_window_rest_prefix_s = 0.0;
  EXPECT_EQ(validationError(o.init), "");
  o.init.gyro_bias_window_rest_block_s = 0.0;
  EXPECT_NE(validationError(o.init).find("gyro_bias_window_rest_block_s"), std::string::npos);
}

}  // namespace
}  // namespace evio::estimator

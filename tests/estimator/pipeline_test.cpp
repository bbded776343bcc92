// The estimator pipeline end to end on tiny sequence folders
// (support/tiny_sequence.h): the backend on exact ground-truth tracks with
// pixel noise (method tracks), the estimate folder it writes, determinism,
// calib.txt-only folders, and every kind of bad input (an evio::Error with
// one clear message, or a status — never a crash).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/status_yaml.h"
#include "evio/core/io/timing_txt.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/io/tum.h"
#include "evio/estimator/pipeline/groundtruth_init.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "temp_dir.h"
#include "support/timing_columns.h"
#include "support/tiny_sequence.h"

namespace evio::estimator {
namespace {

namespace fs = std::filesystem;

/// A method's defaults started from the ground truth (the paper's protocol,
/// which a run gets only when it asks for it).
PipelineOptions fromGroundTruth(std::string_view method) {
  PipelineOptions o = PipelineOptions::forMethod(method);
  o.init.mode = "groundtruth";
  return o;
}

PipelineOptions tracksOptions(double noise_px = 0.5) {
  PipelineOptions o = fromGroundTruth("tracks");
  o.tracks.noise_px = noise_px;
  o.backend.sigma_img_px = 1.0;
  o.backend.slam_min_depth_m = 1.5;  // the landmarks are 2-5 m away
  return o;
}

/// Largest position error of the estimate against the ground truth (m), after `skip_s`.
double maxPositionError(const std::string& estimate, const std::string& groundtruth, double skip_s = 0.0) {
  const Trajectory est = io::readTum(estimate);
  const Trajectory gt = io::readTum(groundtruth);
  double worst = 0.0;
  for (const auto& p : est) {
    if (p.t_ns < gt.front().t_ns + secondsToNs(skip_s) || p.t_ns > gt.back().t_ns) continue;
    worst = std::max(worst, (p.pose.translation() - interpolatePose(gt, p.t_ns).translation()).norm());
  }
  return worst;
}

void expectErrorContaining(const std::function<void()>& fn, const std::vector<std::string>& needles) {
  try {
    fn();
  } catch (const Error& e) {
    for (const auto& n : needles) EXPECT_NE(std::string(e.what()).find(n), std::string::npos) << e.what();
    return;
  }
  ADD_FAILURE() << "no evio::Error";
}

// --- end to end on ground-truth tracks -------------------------------------------------------

TEST(Pipeline, TracksMethodFollowsTheGroundTruthAndWritesTheEstimateFolder) {
  test::TempDir dir;
  const std::string seq = dir.file("seq"), out = dir.file("out");
  test::TinySequenceOptions so;
  writeTinySequence(seq, so);
  const PipelineOptions options = tracksOptions();
  const PipelineResult r = runPipeline(seq, options, out);

  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  ASSERT_TRUE(r.initialization_t_ns.has_value());
  EXPECT_EQ(*r.initialization_t_ns, 0);
  EXPECT_EQ(r.counts.measurement_sets, 80u);  // 20 Hz over 4 s
  EXPECT_EQ(r.counts.poses, 80u);
  EXPECT_GT(r.backend.slam_initialized_prior + r.backend.slam_initialized_triangulated, 0);
  // Initialised from ground truth, the estimate stays within 5 cm over 4 s
  // (0.5 px noise, six_dof motion of a few cm and degrees).
  EXPECT_LT(maxPositionError(out + "/trajectory.txt", seq + "/groundtruth.txt"), 0.05);

  // Every file is there and reads back through core/io.
  const Trajectory traj = io::readTum(out + "/trajectory.txt");
  const auto cov = io::readTumCovariance(out + "/trajectory_covariance.txt");  // validates PSD
  ASSERT_EQ(cov.size(), traj.size());
  for (std::size_t k = 0; k < traj.size(); ++k) {
    EXPECT_EQ(cov[k].t_ns, traj[k].t_ns);
    EXPECT_GT(cov[k].cov_orientation.trace(), 0.0);
  }
  EXPECT_EQ(io::readImuStateText(out + "/imu_state.txt").size(), traj.size());
  const auto timing = io::readTimingText(out + "/timing.txt");
  ASSERT_GE(timing.size(), 2u);
  EXPECT_EQ(timing.front().t_ns, 0);                        // written at initialisation
  EXPECT_GE(timing.back().t_ns, secondsToNs(3.9));          // up to the end
  const io::EstimateStatus status = io::readStatusYaml(out + "/status.yaml");
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.initialization_t_ns, std::optional<TimeNs>(0));
  PipelineOptions back;
  config::fill(config::loadFile(out + "/config.yaml"), "", back);
  // config.yaml records the options as run: the frontend's sensor-dependent
  // values filled in from the event camera's calibration.
  PipelineOptions expected = options;
  const SensorRig rig = io::readSensorsYaml(seq + "/sensors.yaml");
  expected.frontend = resolveSensorParameters(options.frontend, rig.firstCamera(CameraRole::kEvent)->parameters);
  EXPECT_NE(expected.frontend.eklt.batch_contrast_threshold, 0.0);
  EXPECT_TRUE(config::equal(back, expected));
  EXPECT_TRUE(fs::exists(out + "/summary.yaml"));
}

// timing.txt's features column holds the size of the latest measurement set
// at or before each row's time. With the `tracks` method at 20 Hz on file
// times every 10 ms from 0, the sets come at 50, 100, 150 ms, … (the first
// one period after the first point, synchronizer.cpp) and the set at a
// multiple of 50 ms holds exactly the file's samples at that time
// (tracks_input.h), so the expected count of a row at t is the number of
// truth/tracks.txt samples at floor(t / 50 ms), and 0 for the row at
// initialisation (t = 0, before the first set).
TEST(Pipeline, TimingFeaturesAreTheSizeOfTheLatestMeasurementSet) {
  test::TempDir dir;
  const std::string seq = dir.file("seq"), out = dir.file("out");
  test::TinySequenceOptions so;
  so.duration_s = 3.0;
  writeTinySequence(seq, so);
  std::map<TimeNs, std::int64_t> samples_at;
  for (const io::TrackSample& s : io::readTracksText(seq + "/truth/tracks.txt")) ++samples_at[s.t_ns];
  const PipelineResult r = runPipeline(seq, tracksOptions(), out);
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  const auto timing = io::readTimingText(out + "/timing.txt");
  ASSERT_GE(timing.size(), 25u);  // a row every 0.1 s of data
  const TimeNs period = 50'000'000;
  std::set<std::int64_t> counts;
  for (const io::TimingSample& row : timing) {
    ASSERT_TRUE(row.features.has_value());
    const TimeNs set_t = row.t_ns / period * period;
    ASSERT_EQ(samples_at.count(set_t), 1u) << set_t;
    const std::int64_t expected = set_t == 0 ? 0 : samples_at[set_t];
    EXPECT_EQ(*row.features, expected) << "row at " << nsToSeconds(row.t_ns) << " s";
    counts.insert(*row.features);
  }
  std::printf("timing.txt: %zu rows, feature counts %lld to %lld\n", timing.size(),
              static_cast<long long>(*counts.begin()), static_cast<long long>(*counts.rbegin()));
}

TEST(Pipeline, SameInputSameSeedGivesIdenticalTrajectories) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  writeTinySequence(seq, so);
  runPipeline(seq, tracksOptions(), dir.file("a"));
  runPipeline(seq, tracksOptions(), dir.file("b"));
  EXPECT_EQ(io::readFile(dir.file("a/trajectory.txt")), io::readFile(dir.file("b/trajectory.txt")));
  EXPECT_EQ(io::readFile(dir.file("a/trajectory_covariance.txt")), io::readFile(dir.file("b/trajectory_covariance.txt")));
  PipelineOptions other = tracksOptions();
  other.seed = 2;  // other track noise
  runPipeline(seq, other, dir.file("c"));
  EXPECT_NE(io::readFile(dir.file("a/trajectory.txt")), io::readFile(dir.file("c/trajectory.txt")));
}

TEST(Pipeline, NormalisedImageNoiseEqualsPixelNoiseOverTheFocalLength) {
  // The tiny camera has f = 200 px: σ = 1 px is 0.005 in normalised units.
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  writeTinySequence(seq, so);
  runPipeline(seq, tracksOptions(), dir.file("px"));
  PipelineOptions normalised = tracksOptions();
  normalised.backend.sigma_img_px = 123.0;  // ignored when sigma_img_normalized > 0
  normalised.backend.sigma_img_normalized = 1.0 / 200.0;
  runPipeline(seq, normalised, dir.file("norm"));
  EXPECT_EQ(io::readFile(dir.file("px/trajectory_covariance.txt")), io::readFile(dir.file("norm/trajectory_covariance.txt")));
  normalised.backend.sigma_img_normalized = 2.0 / 200.0;
  runPipeline(seq, normalised, dir.file("norm2"));
  EXPECT_NE(io::readFile(dir.file("px/trajectory_covariance.txt")), io::readFile(dir.file("norm2/trajectory_covariance.txt")));
}

TEST(Pipeline, CalibTxtFolderTakesTheRestFromTheConfiguration) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.sensors_yaml = false;
  so.duration_s = 2.0;
  writeTinySequence(seq, so);
  PipelineOptions o = tracksOptions();
  // Without frames the size must come from the configuration.
  expectErrorContaining([&] { runPipeline(seq, o, dir.file("out0")); }, {"calibration.width"});
  o.calibration.width = 240;
  o.calibration.height = 180;
  o.calibration.T_B_C = test::tinyT_B_C().matrix();
  const PipelineResult r = runPipeline(seq, o, dir.file("out"));
  EXPECT_EQ(r.rig_source, "calib.txt");
  ASSERT_TRUE(r.status.ok()) << r.status.cause;
  EXPECT_LT(maxPositionError(dir.file("out/trajectory.txt"), seq + "/groundtruth.txt"), 0.05);
}

// --- IMU gaps (documented degraded mode) --------------------------------------------------------

TEST(PipelineBadInput, ShortImuGapIsBridgedAndCounted) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 3.0;
  so.imu_gaps_s = {{1.5, 1.7}};  // 0.2 s: above imu_max_gap_s (0.05), below imu_fail_gap_s (1)
  writeTinySequence(seq, so);
  const PipelineResult r = runPipeline(seq, tracksOptions(), dir.file("out"));
  EXPECT_TRUE(r.status.ok()) << r.status.cause;
  EXPECT_EQ(r.backend.imu_gaps, 1);
  EXPECT_GE(io::readTum(dir.file("out/trajectory.txt")).back().t_ns, secondsToNs(2.9));
}

TEST(PipelineBadInput, LongImuGapFailsWithItsTimeAndKeepsTheTrajectoryBeforeIt) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 4.0;
  so.imu_gaps_s = {{1.5, 3.0}};
  writeTinySequence(seq, so);
  const PipelineResult r = runPipeline(seq, tracksOptions(), dir.file("out"));
  EXPECT_EQ(r.status.code, io::EstimateStatus::Code::kFailed);
  EXPECT_NE(r.status.cause.find("IMU gap"), std::string::npos) << r.status.cause;
  ASSERT_TRUE(r.status.t_ns.has_value());
  EXPECT_NEAR(nsToSeconds(*r.status.t_ns), 1.5, 0.11);  // the filter lags the IMU by at most max_delay_s
  const io::EstimateStatus written = io::readStatusYaml(dir.file("out/status.yaml"));
  EXPECT_EQ(written, r.status);
  const Trajectory traj = io::readTum(dir.file("out/trajectory.txt"));
  ASSERT_FALSE(traj.empty());
  EXPECT_LT(traj.back().t_ns, secondsToNs(1.5));
}

TEST(PipelineBadInput, ImuEndingWhileFramesContinueFails) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 3.0;
  so.frames = 60;
  so.imu_end_s = 1.0;
  writeTinySequence(seq, so);
  const PipelineResult r = runPipeline(seq, fromGroundTruth("klt-vio"), dir.file("out"));
  EXPECT_EQ(r.status.code, io::EstimateStatus::Code::kFailed);
  EXPECT_NE(r.status.cause.find("no IMU reading after"), std::string::npos) << r.status.cause;
}

// The backend on its own thread (backend_thread) stops at the same item when
// the run fails: the same status, files and counts as on one thread, though
// the reading side ran ahead.
TEST(PipelineBadInput, BackendThreadFailsAtTheSameItemAsOneThread) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 4.0;
  so.frames = 80;
  so.imu_gaps_s = {{1.5, 3.0}};
  writeTinySequence(seq, so);
  for (const char* method : {"tracks", "klt-vio"}) {
    PipelineOptions one = std::string(method) == "tracks" ? tracksOptions() : fromGroundTruth(method);
    PipelineOptions two = one;
    two.backend_thread = true;
    const PipelineResult r1 = runPipeline(seq, one, dir.file(std::string(method) + "_1"));
    const PipelineResult r2 = runPipeline(seq, two, dir.file(std::string(method) + "_2"));
    EXPECT_EQ(r1.status.code, io::EstimateStatus::Code::kFailed) << method;
    EXPECT_EQ(r1.status, r2.status) << method;
    EXPECT_EQ(r1.t_last_ns, r2.t_last_ns) << method;
    EXPECT_EQ(r1.counts.imu_samples, r2.counts.imu_samples) << method;
    EXPECT_EQ(r1.counts.frames, r2.counts.frames) << method;
    EXPECT_EQ(r1.counts.measurement_sets, r2.counts.measurement_sets) << method;
    for (const char* file : {"trajectory.txt", "trajectory_covariance.txt", "status.yaml"})
      EXPECT_EQ(io::readFile(dir.file(std::string(method) + "_1/" + file)),
                io::readFile(dir.file(std::string(method) + "_2/" + file)))
          << method << " " << file;
    const test::TimingColumns timing = test::timingWithoutClock(dir.file(std::string(method) + "_1/timing.txt"));
    EXPECT_TRUE(test::anyFeatures(timing)) << method;
    EXPECT_EQ(timing, test::timingWithoutClock(dir.file(std::string(method) + "_2/timing.txt"))) << method;
  }
}

// --- other bad input: one clear evio::Error ------------------------------------------------------

TEST(PipelineBadInput, EventsOutOfOrderNameTheFileAndLine) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 1.0;
  so.frames = 10;
  writeTinySequence(seq, so);
  io::writeFileAtomic(seq + "/events.txt", "0.001 10 10 1\n0.002 11 10 0\n0.0015 12 10 1\n0.003 13 10 1\n");
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("eklt-vio"), dir.file("out")); },
                        {"events.txt:3"});
  EXPECT_FALSE(fs::exists(dir.file("out/trajectory.txt")));  // nothing half-written
  PipelineOptions threaded = fromGroundTruth("eklt-vio");
  threaded.backend_thread = true;
  threaded.frontend.threads = 2;
  expectErrorContaining([&] { runPipeline(seq, threaded, dir.file("out2")); }, {"events.txt:3"});
  EXPECT_FALSE(fs::exists(dir.file("out2/trajectory.txt")));
}

TEST(PipelineBadInput, NoFramesForFrameBasedTrackingSaysWhatToDo) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 1.0;
  so.events = true;
  writeTinySequence(seq, so);
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("eklt-vio"), dir.file("out")); },
                        {"no frames", "frontend.image_source=reconstructed"});
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("klt-vio"), dir.file("out")); },
                        {"no frames", "KLT-VIO needs frames"});
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("haste-vio"), dir.file("out")); },
                        {"no frames", "frontend.image_source=reconstructed"});
  // The documented alternative runs.
  PipelineOptions o = fromGroundTruth("eklt-vio");
  o.frontend.image_source = "reconstructed";
  EXPECT_NO_THROW(runPipeline(seq, o, dir.file("out")));
  PipelineOptions h = fromGroundTruth("haste-vio");
  h.frontend.image_source = "reconstructed";
  EXPECT_NO_THROW(runPipeline(seq, h, dir.file("out_haste")));
}

TEST(PipelineBadInput, FrameSizeNotTheCalibrationsNamesBoth) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 1.0;
  so.frames = 5;
  so.frame_width = 200;
  so.frame_height = 150;
  so.events = true;
  writeTinySequence(seq, so);
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("klt-vio"), dir.file("out")); },
                        {"200x150", "240x180", "sensors.yaml camera frames"});
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("eklt-vio"), dir.file("out")); },
                        {"200x150", "240x180", "sensors.yaml camera cam0"});
}

TEST(PipelineBadInput, EventSensorSizeNotTheCalibrationsNamesBoth) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 1.0;
  so.frames = 5;
  writeTinySequence(seq, so);
  EventArray events;
  events.push_back(1000, 300, 10, true);
  io::EventH5Options h5;
  h5.width = 346;
  h5.height = 260;
  io::writeEventsH5(seq + "/events.h5", events, h5);
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("eklt-vio"), dir.file("out")); },
                        {"events.h5", "346x260", "240x180"});
  // events.txt with a pixel outside the calibrated sensor.
  fs::remove(seq + "/events.h5");
  io::writeFileAtomic(seq + "/events.txt", "0.001 10 10 1\n0.002 300 10 0\n");
  expectErrorContaining([&] { runPipeline(seq, fromGroundTruth("eklt-vio"), dir.file("out")); },
                        {"events.txt:2", "240x180"});
}

TEST(PipelineBadInput, InitialisationNeedsGroundTruthOrStaticMode) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  so.groundtruth = false;
  writeTinySequence(seq, so);
  expectErrorContaining([&] { runPipeline(seq, tracksOptions(), dir.file("out")); },
                        {"no groundtruth.txt", "--init static"});
  // static: the hand-held motion is never still, so the run ends "failed" (not initialised).
  PipelineOptions o = tracksOptions();
  o.init.mode = "static";
  const PipelineResult r = runPipeline(seq, o, dir.file("out"));
  EXPECT_EQ(r.status.code, io::EstimateStatus::Code::kFailed);
  EXPECT_NE(r.status.cause.find("never initialised"), std::string::npos) << r.status.cause;
  EXPECT_EQ(r.counts.poses, 0u);
  // `auto` is gone: it used to pick ground truth whenever the file existed.
  o.init.mode = "auto";
  expectErrorContaining([&] { runPipeline(seq, o, dir.file("out")); }, {"init.mode", "auto is gone"});
}

TEST(Pipeline, GroundTruthIsReadOnlyWhenAskedFor) {
  // A sequence that ships ground truth: the default (static) never reads it,
  // so the hand-held run cannot initialise; asked for, it starts from it. The
  // resolved configuration and the summary say which ran.
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  writeTinySequence(seq, so);
  PipelineOptions o = PipelineOptions::forMethod("tracks");
  EXPECT_EQ(o.init.mode, "static");
  const PipelineResult r_static = runPipeline(seq, o, dir.file("static"));
  EXPECT_EQ(r_static.status.code, io::EstimateStatus::Code::kFailed);
  EXPECT_FALSE(r_static.initialization_t_ns.has_value());
  const PipelineResult r_gt = runPipeline(seq, tracksOptions(), dir.file("gt"));
  EXPECT_EQ(r_gt.status.code, io::EstimateStatus::Code::kOk);
  EXPECT_TRUE(r_gt.initialization_t_ns.has_value());
  const auto read = [](const std::string& path) { return io::readFile(path); };
  EXPECT_NE(read(dir.file("static/config.yaml")).find("mode: static"), std::string::npos);
  EXPECT_NE(read(dir.file("gt/config.yaml")).find("mode: groundtruth"), std::string::npos);
  EXPECT_NE(read(dir.file("gt/summary.yaml")).find("initialization: groundtruth"), std::string::npos);
}

TEST(Pipeline, UseRangeFeedsEveryValidRangeReadingToTheBackend) {
  test::TempDir dir;
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 2.0;
  writeTinySequence(seq, so);
  PipelineOptions o = tracksOptions();
  o.backend.use_range = true;
  // The rig has no range finder: one error naming the option, and no output.
  expectErrorContaining([&] { runPipeline(seq, o, dir.file("out")); }, {"backend.use_range", "no range finder"});
  EXPECT_FALSE(fs::exists(dir.file("out")));
  SensorRig rig = io::readSensorsYaml(seq + "/sensors.yaml");
  rig.range_finder = RangeFinderSensor{Pose(), 0.1, 50.0, 0.02};
  io::writeSensorsYaml(seq + "/sensors.yaml", rig);
  // 20 Hz readings up to 1.75 s of the 2 s run (a reading waits for
  // backend.max_delay_s = 0.1 s of IMU after it), every fourth without a return.
  std::vector<io::RangeSample> ranges;
  int valid = 0;
  for (int k = 1; k <= 35; ++k) {
    ranges.push_back(io::RangeSample{secondsToNs(0.05 * k), k % 4 == 0 ? 0.0 : 3.0, k % 4 != 0});
    valid += k % 4 != 0;
  }
  io::writeRangeText(seq + "/range.txt", ranges);
  const PipelineResult r = runPipeline(seq, o, dir.file("out"));
  // Each valid reading is either an update or rejected (the tiny scene is no plane under the beam).
  EXPECT_EQ(r.backend.range_updates + r.backend.range_rejected, valid);
  o.backend.use_range = false;
  const PipelineResult off = runPipeline(seq, o, dir.file("off"));
  EXPECT_EQ(off.backend.range_updates + off.backend.range_rejected, 0);
}

TEST(PipelineBadInput, MissingFolderOrCalibrationIsAnError) {
  test::TempDir dir;
  expectErrorContaining([&] { runPipeline(dir.file("nope"), tracksOptions(), dir.file("out")); }, {"not a folder"});
  const std::string seq = dir.file("seq");
  test::TinySequenceOptions so;
  so.duration_s = 1.0;
  writeTinySequence(seq, so);
  fs::remove(seq + "/sensors.yaml");
  expectErrorContaining([&] { runPipeline(seq, tracksOptions(), dir.file("out")); },
                        {"neither sensors.yaml nor calib.txt"});
}

}  // namespace
}  // namespace evio::estimator

// The pipelines end to end on a sequence from the simulator (ctest label
// `slow`): the first 2 s of experiments/scenarios/poster_6dof.yaml, simulated
// once, then EKLT-VIO, KLT-VIO and the backend on the simulator's
// ground-truth tracks with 0.5 px noise, each with the configuration for
// simulated sequences (estimator/config/sim.yaml, what campaigns and the
// README run: the simulator's IMU noise, the paper's n_e). Each must stay ok
// and, initialised
// from ground truth, within 10 cm of it (the hand-held motion of the first
// seconds spans a few centimetres and degrees; IMU-only dead reckoning at the
// DAVIS240 reference noise with zero-bias start drifts further than that).
#include <gtest/gtest.h>

#include <algorithm>

#include <string>
#include <utility>
#include <vector>

#include "evio/core/io/atomic_file.h"
#include "evio/core/io/config.h"
#include "evio/core/io/tum.h"
#include "evio/estimator/pipeline/groundtruth_init.h"
#include "evio/estimator/pipeline/method_settings.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "evio/simulator/sequence_simulator.h"
#include "support/timing_columns.h"
#include "temp_dir.h"

namespace evio::estimator {
namespace {

/// A method with estimator/config/sim.yaml started from the ground truth
/// (`evio estimate --config estimator/config/sim.yaml --init groundtruth`,
/// the method's own section of the file included).
PipelineOptions fromGroundTruth(std::string_view method) {
  PipelineOptions o = PipelineOptions::forMethod(method);
  config::Document doc = config::loadFile(std::string(EVIO_SOURCE_DIR) + "/estimator/config/sim.yaml");
  applyMethodSettings(doc, method);
  config::fill(doc, "", o);
  o.init.mode = "groundtruth";
  return o;
}

double maxPositionError(const std::string& estimate, const std::string& groundtruth) {
  const Trajectory est = io::readTum(estimate);
  const Trajectory gt = io::readTum(groundtruth);
  double worst = 0.0;
  for (const auto& p : est) {
    if (p.t_ns < gt.front().t_ns || p.t_ns > gt.back().t_ns) continue;
    worst = std::max(worst, (p.pose.translation() - interpolatePose(gt, p.t_ns).translation()).norm());
  }
  return worst;
}

class PipelineSimulated : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    const simulator::Scenario scenario = simulator::loadScenario(
        std::string(EVIO_SOURCE_DIR) + "/experiments/scenarios/poster_6dof.yaml",
        {"duration_s=2", "output.write_events_txt=false", "threads=0",
         // The legacy event pixel: this suite checks the pipelines end to end at
         // the event density it was built for (an update per 3200 events, more
         // than one per frame). The calibrated pixel gives a third of the events
         // in these slow first seconds; what EKLT-VIO does with them is for the
         // campaigns (docs/consistency.md "Consistency").
         "rig.event_camera.preset=simulator/presets/davis240c_legacy.yaml"},
        EVIO_SOURCE_DIR);
    simulator::simulateSequence(scenario, sequence());
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string sequence() { return dir_->file("poster"); }

  static void runAndCheck(PipelineOptions options, const std::string& name, std::uint64_t min_poses) {
    const std::string out = dir_->file(name);
    const PipelineResult r = runPipeline(sequence(), options, out);
    EXPECT_TRUE(r.status.ok()) << name << ": " << r.status.cause;
    EXPECT_GE(r.counts.poses, min_poses) << name;
    const double err = maxPositionError(out + "/trajectory.txt", sequence() + "/groundtruth.txt");
    std::printf("%s: %llu poses, %llu measurement sets, max position error %.4f m\n", name.c_str(),
                static_cast<unsigned long long>(r.counts.poses), static_cast<unsigned long long>(r.counts.measurement_sets), err);
    EXPECT_LT(err, 0.10) << name;
  }

  static std::string file(const std::string& name) { return dir_->file(name); }
  static void expectSameOutputsForAnyThreadCountAndSegment(const std::string& name, bool diverge);

  static test::TempDir* dir_;
};

test::TempDir* PipelineSimulated::dir_ = nullptr;

TEST_F(PipelineSimulated, EkltVio) {
  PipelineOptions o = fromGroundTruth("eklt-vio");
  runAndCheck(o, "eklt", 60);  // an update every 3200 events: more than one per frame
}

// Features tracked on 1, 2 or 3 threads (frontend.threads), the backend on
// the reading thread or its own (backend_thread), event chunks tracked one
// by one or, with threads, in segments (frontend.segment_s: 0, 0.01 and
// 0.02 s, which close on time between the 46 ms frames, the default 0.05 s
// and 1 s, which close at frames): every output file but timing.txt's clock
// and the counts are the same bytes (eklt_tracker.h: fixed partition, merge
// in the single-thread order; stages.h: held inputs leave in their order;
// pipeline.cpp: one backend work per input, with the snapshot taken when it
// was read). `diverge` caps the velocity so that the backend diverges at
// 0.14 m/s and the run stops there: the same item for every configuration.
void PipelineSimulated::expectSameOutputsForAnyThreadCountAndSegment(const std::string& name, bool diverge) {
  struct Config {
    int threads;
    bool backend_thread;
    double segment_s;
  };
  const double kDefault = FrontendOptions().segment_s;
  const Config configs[] = {{1, false, kDefault}, {2, false, kDefault}, {3, false, kDefault}, {1, true, kDefault},
                            {2, true, kDefault},  {2, false, 0.0},      {2, false, 0.01},     {2, true, 0.02},
                            {2, false, 1.0}};
  std::vector<std::string> outs;
  std::vector<PipelineCounts> counts;
  for (const Config& c : configs) {
    PipelineOptions o = fromGroundTruth("eklt-vio");
    o.frontend.threads = c.threads;
    o.backend_thread = c.backend_thread;
    o.frontend.segment_s = c.segment_s;
    o.frontend.eklt.position_covariance = true;
    if (diverge) o.backend.max_velocity_mps = 0.14;
    outs.push_back(file(name + "_" + std::to_string(c.threads) + (c.backend_thread ? "_bt" : "") + "_seg" +
                                std::to_string(c.segment_s)));
    const PipelineResult r = runPipeline(sequence(), o, outs.back());
    if (diverge) {
      ASSERT_EQ(r.status.code, io::EstimateStatus::Code::kDiverged) << r.status.cause;
      ASSERT_NE(r.status.cause.find("max_velocity_mps"), std::string::npos) << r.status.cause;
      ASSERT_GT(r.counts.measurement_sets, 5u);
    } else {
      ASSERT_TRUE(r.status.ok()) << r.status.cause;
      ASSERT_GT(r.counts.measurement_sets, 60u);
    }
    counts.push_back(r.counts);
  }
  for (std::size_t k = 1; k < outs.size(); ++k) {
    const std::string config = std::to_string(configs[k].threads) + " threads" +
                               (configs[k].backend_thread ? " + backend thread" : "") + ", segments of " +
                               std::to_string(configs[k].segment_s) + " s";
    for (const char* file : {"trajectory.txt", "trajectory_covariance.txt", "imu_state.txt", "health.txt", "status.yaml"})
      EXPECT_TRUE(io::readFile(outs[0] + "/" + file) == io::readFile(outs[k] + "/" + file)) << file << ", " << config;
    // timing.txt: the same rows, events and features (the processing time is the machine's).
    EXPECT_TRUE(test::timingWithoutClock(outs[0] + "/timing.txt") == test::timingWithoutClock(outs[k] + "/timing.txt"))
        << config;
    EXPECT_EQ(counts[0].events, counts[k].events) << config;
    EXPECT_EQ(counts[0].events_kept, counts[k].events_kept) << config;
    EXPECT_EQ(counts[0].frames, counts[k].frames) << config;
    EXPECT_EQ(counts[0].imu_samples, counts[k].imu_samples) << config;
    EXPECT_EQ(counts[0].track_points, counts[k].track_points) << config;
    EXPECT_EQ(counts[0].measurement_sets, counts[k].measurement_sets) << config;
    EXPECT_EQ(counts[0].poses, counts[k].poses) << config;
  }
  EXPECT_FALSE(io::readFile(outs[0] + "/trajectory.txt").empty());
  EXPECT_TRUE(test::anyFeatures(test::timingWithoutClock(outs[0] + "/timing.txt")));
}

TEST_F(PipelineSimulated, EkltVioOutputsAreByteIdenticalForAnyThreadCountAndSegment) {
  expectSameOutputsForAnyThreadCountAndSegment("eklt", false);
}

TEST_F(PipelineSimulated, EkltVioStopsAtTheSameItemForAnyThreadCountAndSegment) {
  expectSameOutputsForAnyThreadCountAndSegment("eklt_diverging", true);
}

// A 50 ms refractory filter and random halving before the tracker thin the
// chunks inside a segment (some may hold no event): still the same files.
TEST_F(PipelineSimulated, EkltVioWithPrefiltersIsTheSameWithSegments) {
  std::vector<std::string> outs;
  for (const double segment_s : {0.0, 0.01}) {
    PipelineOptions o = fromGroundTruth("eklt-vio");
    o.frontend.threads = 2;
    o.frontend.segment_s = segment_s;
    o.frontend.prefilter.refractory_period_s = 0.05;
    o.frontend.prefilter.random_keep_one_in = 2;
    outs.push_back(file("eklt_prefiltered_seg" + std::to_string(segment_s)));
    const PipelineResult r = runPipeline(sequence(), o, outs.back());
    ASSERT_GT(r.counts.track_points, 500u) << r.status.cause;
    ASSERT_LT(r.counts.events_kept, r.counts.events / 2);
  }
  for (const char* file : {"trajectory.txt", "trajectory_covariance.txt", "imu_state.txt", "health.txt", "status.yaml"})
    EXPECT_TRUE(io::readFile(outs[0] + "/" + file) == io::readFile(outs[1] + "/" + file)) << file;
  EXPECT_TRUE(test::timingWithoutClock(outs[0] + "/timing.txt") == test::timingWithoutClock(outs[1] + "/timing.txt"));
}

// HASTE-VIO alike: 1 thread against 2 tracker threads and the backend
// thread. (Its accuracy on these 2 s is not the point: with the defaults of
// 5b9aa9a the self-diagnosis calls the run degraded; the status must be the
// same bytes too.)
TEST_F(PipelineSimulated, HasteVioEstimatesAreByteIdenticalForAnyThreadCount) {
  std::vector<std::string> outs;
  for (int run : {1, 2, 3}) {  // 1 thread; 2 threads, segments, backend thread; 2 threads without segments
    PipelineOptions o = fromGroundTruth("haste-vio");
    o.frontend.threads = run == 1 ? 1 : 2;
    o.backend_thread = run == 2;
    if (run == 3) o.frontend.segment_s = 0.0;
    outs.push_back(dir_->file("haste_run_" + std::to_string(run)));
    const PipelineResult r = runPipeline(sequence(), o, outs.back());
    ASSERT_GT(r.counts.measurement_sets, 30u) << r.status.cause;
    ASSERT_GT(r.counts.track_points, 1000u);
  }
  for (std::size_t k = 1; k < outs.size(); ++k)
    for (const char* file : {"trajectory.txt", "trajectory_covariance.txt", "imu_state.txt", "health.txt", "status.yaml"})
      EXPECT_TRUE(io::readFile(outs[0] + "/" + file) == io::readFile(outs[k] + "/" + file)) << file << ", run " << k;
  const test::TimingColumns timing = test::timingWithoutClock(outs[0] + "/timing.txt");
  EXPECT_TRUE(test::anyFeatures(timing));
  EXPECT_TRUE(timing == test::timingWithoutClock(outs[1] + "/timing.txt"));
}

TEST_F(PipelineSimulated, KltVio) { runAndCheck(fromGroundTruth("klt-vio"), "klt", 40); }

TEST_F(PipelineSimulated, BackendOnNoisyGroundTruthTracks) {
  PipelineOptions o = fromGroundTruth("tracks");
  o.tracks.noise_px = 0.5;
  runAndCheck(o, "tracks", 35);
}

}  // namespace
}  // namespace evio::estimator

// End-to-end consistency of EKLT-VIO and KLT-VIO (ctest label `slow`): 20
// seeds of the first 2 s of experiments/scenarios/poster_6dof.yaml, each
// simulated once, each method started from the ground truth with the
// shipped estimator/config/sim.yaml settings, scored as `evio evaluate
// --paper` scores NEES (errors in the truth frame the filter starts in).
// The average pose NEES over the runs must lie inside the two-sided 95 %
// bounds χ²_{0.025, 0.975}(6R)/R of R runs: both bounds are checked, so an
// under-confident filter fails as surely as an over-confident one.
//
// Both FAIL today, as under-confident: measured ANEES 0.245 (EKLT-VIO) and
// 0.016 (KLT-VIO) against [4.58, 7.61], 91 s of user CPU for the suite (20
// simulations, 40 estimates). Started exactly at the truth, the filters
// carry their initial attitude, velocity and bias σ (3°, 0.05 m/s, 6°/s,
// 0.3 m/s²) for an error that starts at zero; the first 2 s measure that
// prior more than the measurement model. Issue 18.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "evio/core/io/config.h"
#include "evio/core/io/tum.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/pipeline/pipeline.h"
#include "evio/experiments/trajectory_metrics.h"
#include "evio/simulator/sequence_simulator.h"
#include "temp_dir.h"

namespace evio::estimator {
namespace {

constexpr int kSeeds = 20;

class PipelineConsistency : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const simulator::Scenario scenario = simulator::loadScenario(
          std::string(EVIO_SOURCE_DIR) + "/experiments/scenarios/poster_6dof.yaml",
          {"duration_s=2", "seed=" + std::to_string(seed), "output.write_events_txt=false", "threads=0"},
          EVIO_SOURCE_DIR);
      simulator::simulateSequence(scenario, sequence(seed));
    }
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static std::string sequence(int seed) { return dir_->file("poster_" + std::to_string(seed)); }

  /// The shipped simulated-sequence configuration for `method`, from ground truth.
  static PipelineOptions shippedOptions(const std::string& method) {
    config::Document doc = config::loadFile(std::string(EVIO_SOURCE_DIR) + "/estimator/config/sim.yaml");
    config::applyOverride(doc, "method=" + method);
    config::applyOverride(doc, "init.mode=groundtruth");
    PipelineOptions o = PipelineOptions::forMethod(method);
    config::fill(doc, "", o);
    return o;
  }

  /// Average pose NEES of one run, in the truth frame (no alignment).
  static double runNees(const std::string& method, int seed) {
    const std::string out = dir_->file(method + "_" + std::to_string(seed));
    const PipelineResult r = runPipeline(sequence(seed), shippedOptions(method), out);
    EXPECT_TRUE(r.status.ok()) << method << " seed " << seed << ": " << r.status.cause;
    experiments::EvaluationInputs in;
    in.estimate = io::readTum(out + "/trajectory.txt");
    in.groundtruth = io::readTum(sequence(seed) + "/groundtruth.txt");
    in.covariance = io::readTumCovariance(out + "/trajectory_covariance.txt");
    experiments::EvaluationOptions options = experiments::EvaluationOptions::paper();
    options.alignment.window = "all";  // 2 s: the paper's 3–8 s window is empty; NEES does not use it
    const experiments::Metrics m = experiments::evaluateTrajectory(in, options);
    EXPECT_TRUE(m.nees.available) << method << " seed " << seed;
    return m.nees.mean_pose;
  }

  static void expectConsistent(const std::string& method) {
    double sum = 0.0;
    for (int seed = 1; seed <= kSeeds; ++seed) {
      const double nees = runNees(method, seed);
      std::printf("%s seed %d: average pose NEES %.3f\n", method.c_str(), seed, nees);
      sum += nees;
    }
    const double R = kSeeds;
    const double anees = sum / R;
    const double lo = chi2Quantile(0.025, 6 * R) / R, hi = chi2Quantile(0.975, 6 * R) / R;
    std::printf("%s: ANEES %.3f over %d runs, two-sided 95%% bounds [%.3f, %.3f]\n", method.c_str(), anees, kSeeds,
                lo, hi);
    RecordProperty("anees", std::to_string(anees));
    EXPECT_GE(anees, lo) << method << " is under-confident";
    EXPECT_LE(anees, hi) << method << " is over-confident";
  }

  static test::TempDir* dir_;
};

test::TempDir* PipelineConsistency::dir_ = nullptr;

TEST_F(PipelineConsistency, EkltVioAneesInsideTheTwoSided95PercentBounds) { expectConsistent("eklt-vio"); }

TEST_F(PipelineConsistency, KltVioAneesInsideTheTwoSided95PercentBounds) { expectConsistent("klt-vio"); }

}  // namespace
}  // namespace evio::estimator

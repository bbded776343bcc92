// The pipeline's stages (stages.h) and method registry (method.h) on their
// own: what each stage passes on, in which order, with exact answers.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <variant>

#include "evio/core/error.h"
#include "evio/core/io/health_txt.h"
#include "evio/core/io/tum.h"
#include "evio/estimator/pipeline/health_monitor.h"
#include "evio/estimator/pipeline/method.h"
#include "evio/estimator/pipeline/pipeline_options.h"
#include "evio/estimator/pipeline/stages.h"
#include "temp_dir.h"

namespace evio::estimator {
namespace {

SequenceItem eventsItem(std::vector<std::pair<TimeNs, int>> t_x) {
  SequenceItem item;
  item.kind = SequenceItem::Kind::kEvents;
  for (const auto& [t, x] : t_x) item.events.push_back(t, static_cast<std::uint16_t>(x), 5, true);
  item.t_ns = item.events.t().back();
  return item;
}

SequenceItem imuItem(TimeNs t_cam_ns, TimeNs offset_ns = 0) {
  SequenceItem item;
  item.kind = SequenceItem::Kind::kImu;
  item.t_ns = t_cam_ns;
  item.imu.t_ns = t_cam_ns + offset_ns;
  item.imu.acc_B = Vec3(0, 0, 9.81);
  return item;
}

TEST(PipelineMethods, EveryMethodParsesBackAndSetsItsFrontend) {
  EXPECT_EQ(methodNames(), "eklt-vio, klt-vio, haste-vio, tracks");
  for (const Method m : {Method::kEkltVio, Method::kKltVio, Method::kHasteVio, Method::kTracks}) {
    const MethodInfo& info = methodInfo(m);
    ASSERT_EQ(parseMethod(info.name), m);
    const PipelineOptions o = PipelineOptions::forMethod(info.name);
    EXPECT_EQ(o.methodKind(), m);
    if (*info.tracker) {
      EXPECT_EQ(o.frontend.tracker, info.tracker);
      EXPECT_EQ(o.sync.trigger, info.sync_trigger);
    }
    EXPECT_NO_THROW(o.validate());
  }
  EXPECT_FALSE(parseMethod("haste").has_value());
  EXPECT_THROW(PipelineOptions::forMethod("haste"), Error);
  PipelineOptions o = PipelineOptions::forMethod("klt-vio");
  o.frontend.tracker = "eklt";
  EXPECT_THROW(o.validate(), Error);
  const PipelineOptions haste = PipelineOptions::forMethod("haste-vio");
  EXPECT_EQ(haste.frontend.tracker, "haste");
  EXPECT_EQ(haste.sync.trigger, "events");  // synchronised like EKLT-VIO
}

TEST(PipelineStages, PrefilterPassesEverythingThroughWhenOffAndCountsWhatItDrops) {
  PrefilterStage off(EventPrefilterOptions{}, 20, 10);
  std::vector<SequenceItem> out;
  SequenceItem in = eventsItem({{1000, 1}, {2000, 1}, {3000, 2}});
  off.process(in, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].events.size(), 3u);
  EXPECT_EQ(off.numEventsSeen(), 3u);
  EXPECT_EQ(off.numEventsKept(), 3u);

  EventPrefilterOptions refractory;
  refractory.refractory_period_s = 0.5e-3;  // 0.5 ms per pixel
  PrefilterStage on(refractory, 20, 10);
  out.clear();
  in = eventsItem({{1000, 1}, {200'000, 1}, {300'000, 2}, {900'000, 1}});
  on.process(in, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].events.size(), 3u);  // pixel 1 at 0.2 ms falls in its refractory period
  EXPECT_EQ(on.numEventsSeen(), 4u);
  EXPECT_EQ(on.numEventsKept(), 3u);
  SequenceItem imu = imuItem(1'000'000);
  on.process(imu, out);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[1].kind, SequenceItem::Kind::kImu);
  EXPECT_EQ(on.numEventsSeen(), 4u);
}

TEST(PipelineStages, SynchronizerPassesImuAndValidRangeBeforeTheSetsTheyRelease) {
  SynchronizerOptions so;
  so.trigger = "fixed_rate";
  so.rate_hz = 100.0;  // a set every 10 ms
  SynchronizerStage sync(so);
  std::vector<BackendInput> out;
  FrontendOutput points;
  points.kind = SequenceItem::Kind::kFrame;
  points.t_ns = 1'000'000;
  points.points = {TrackPoint{1, 1'000'000, Vec2(3, 4), 1.0, TrackStatus::kNew}};
  sync.process(points, out);
  EXPECT_EQ(sync.numTrackPoints(), 1u);
  FrontendOutput imu;
  imu.kind = SequenceItem::Kind::kImu;
  imu.t_ns = 25'000'000;
  imu.imu.t_ns = 25'000'000;
  out.clear();
  sync.process(imu, out);
  ASSERT_GE(out.size(), 2u);
  EXPECT_TRUE(std::holds_alternative<ImuSample>(out[0]));
  for (std::size_t i = 1; i < out.size(); ++i) EXPECT_TRUE(std::holds_alternative<MeasurementSet>(out[i]));
  FrontendOutput range;
  range.kind = SequenceItem::Kind::kRange;
  range.t_ns = 26'000'000;
  range.range = io::RangeSample{26'000'000, 2.5, true};
  out.clear();
  sync.process(range, out);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(std::get<RangeMeasurement>(out[0]).range_m, 2.5);
  range.range.valid = false;
  out.clear();
  sync.process(range, out);
  EXPECT_TRUE(out.empty());
}

TEST(PipelineStages, TracksStageReleasesTheSetsUpToEachImuTime) {
  std::vector<io::TrackSample> samples;
  for (int k = 0; k < 5; ++k) samples.push_back(io::TrackSample{1, k * 10'000'000, Vec2(10 + k, 10)});
  TracksInputOptions o;
  o.rate_hz = 0.0;  // every time in the file
  TracksStage stage(std::make_unique<TracksInput>(samples, o, 1));
  std::vector<BackendInput> out;
  SequenceItem imu = imuItem(25'000'000);
  stage.process(imu, out);
  ASSERT_EQ(out.size(), 4u);  // the IMU, then the sets at 0, 10 and 20 ms
  EXPECT_TRUE(std::holds_alternative<ImuSample>(out[0]));
  EXPECT_EQ(std::get<MeasurementSet>(out[3]).t_ns, 20'000'000);
}

TEST(PipelineStages, GroundTruthInitializerWaitsForItsTimeAndStartsFromTheTruth) {
  test::TempDir dir;
  const std::string gt = dir.file("groundtruth.txt");
  Trajectory truth;
  for (int k = 0; k <= 100; ++k)  // 1 m/s along x, from 0.1 s
    truth.push_back(StampedPose{100'000'000 + k * 10'000'000, Pose(Quat::Identity(), Vec3(0.01 * k, 0, 0))});
  io::writeTum(gt, truth);
  const TimeNs offset = 3'000'000;  // t_imu = t_cam + 3 ms
  GroundTruthInitializer init(gt, 0.2, 0.01, Pose(), offset);
  EXPECT_FALSE(init.offer(50'000'000 + offset).has_value());  // before the truth: waits for 0.1 + 0.2 s
  EXPECT_FALSE(init.offer(299'000'000 + offset).has_value());
  const std::optional<ImuState> x0 = init.offer(300'000'000 + offset);
  ASSERT_TRUE(x0.has_value());
  EXPECT_EQ(x0->t_ns, 300'000'000 + offset);
  EXPECT_TRUE(x0->p_W_B.isApprox(Vec3(0.2, 0, 0), 1e-12));
  EXPECT_TRUE(x0->v_W.isApprox(Vec3(1.0, 0, 0), 1e-9));
  GroundTruthInitializer late(gt, 5.0, 0.01, Pose(), 0);
  EXPECT_FALSE(late.offer(100'000'000).has_value());
  EXPECT_THROW(late.offer(5'200'000'000), Error);  // the truth ends at 1.1 s
}

/// An estimate every 10 ms with the given innovations, position σ 1 cm.
Estimate update(int k, double nis, int dof, int accepted = 5) {
  Estimate e;
  e.t_ns = static_cast<TimeNs>(k) * 10'000'000;
  e.innovation = InnovationStats{nis, dof, accepted, 0, nis, dof};  // all accepted
  e.cov_pose_B.diagonal().setConstant(1e-4);
  return e;
}

HealthOptions healthOptions() {
  HealthOptions o;
  o.window_s = 1.0;
  o.min_window_dof = 100;
  o.nis_probability = 0.999;
  o.nis_diverged_ratio = 100.0;
  o.starvation_s = 0.5;
  o.max_position_sigma_m = 0.5;
  return o;
}

TEST(HealthMonitorStage, TheDegradedTestIsTheChiSquaredQuantileOfTheWindow) {
  // 100 updates of 20 dof in the window: degraded exactly when Σ nis > χ²₀.₉₉₉(2000).
  const double q = chi2Quantile(0.999, 2000.0);
  EXPECT_NEAR(q, 2000.0 + 3.0902 * std::sqrt(4000.0), 15.0);  // normal approximation
  for (const double total : {q * 0.999, q * 1.001}) {
    HealthMonitor monitor(healthOptions());
    std::vector<Estimate> out;
    for (int k = 0; k < 100; ++k) {
      Estimate e = update(k, total / 100.0, 20);
      monitor.process(e, out);
    }
    EXPECT_EQ(monitor.verdict().code,
              total > q ? io::EstimateStatus::Code::kDegraded : io::EstimateStatus::Code::kOk);
  }
}

TEST(HealthMonitorStage, ConsistentInnovationsAreOkAndEstimatesPassUnchanged) {
  HealthMonitor monitor(healthOptions());
  std::vector<Estimate> out;
  for (int k = 0; k < 500; ++k) {
    Estimate e = update(k, 20.0, 20);  // ρ = 1 exactly
    monitor.process(e, out);
  }
  EXPECT_EQ(monitor.verdict().code, io::EstimateStatus::Code::kOk);
  ASSERT_EQ(out.size(), 500u);
  EXPECT_EQ(out[123].t_ns, 1'230'000'000);
  EXPECT_EQ(out[123].innovation.nis, 20.0);
}

TEST(HealthMonitorStage, TheWindowedRatioGivesDegradedThenDivergedAtTheirFirstTimes) {
  // ρ = 1 until update 200 (Σ nis = 2000 over the 1 s window of 100 updates,
  // 2000 dof: below χ²₀.₉₉₉(2000) = 2200.1), then each update carries
  // nis = 50·dof: Σ nis = 2000 + 980 n exceeds the quantile at once (n = 1,
  // t = 2.00 s). Then nis = 500·dof from update 400: ρ = (450 m + 5000)/100
  // > 100 first at m = 12 (t = 4.11 s).
  HealthMonitor monitor(healthOptions());
  std::vector<Estimate> out;
  for (int k = 0; k < 600; ++k) {
    const double per_dof = k < 200 ? 1.0 : k < 400 ? 50.0 : 500.0;
    Estimate e = update(k, per_dof * 20.0, 20);
    monitor.process(e, out);
    if (k == 399) {
      EXPECT_EQ(monitor.verdict().code, io::EstimateStatus::Code::kDegraded);
      EXPECT_EQ(monitor.verdict().t_ns, 2'000'000'000);
      EXPECT_NE(monitor.verdict().cause.find("innovations"), std::string::npos);
    }
  }
  EXPECT_EQ(monitor.verdict().code, io::EstimateStatus::Code::kDiverged);
  EXPECT_EQ(monitor.verdict().t_ns, 4'110'000'000);
}

// Exact binomial quantiles (by summing the probabilities):
// P(X ≤ k) ≥ 0.999 first at k = 5, 13, 73, 188 for n = 20, 100, 1000, 3000, p = 0.05.
TEST(HealthMonitorStage, BinomialQuantileIsExact) {
  EXPECT_EQ(binomialQuantile(20, 0.05, 0.999), 5);
  EXPECT_EQ(binomialQuantile(100, 0.05, 0.999), 13);
  EXPECT_EQ(binomialQuantile(1000, 0.05, 0.999), 73);
  EXPECT_EQ(binomialQuantile(3000, 0.05, 0.999), 188);
  EXPECT_EQ(binomialQuantile(0, 0.05, 0.999), 0);
}

// Rejected innovations, however large, never make a run `diverged`: the
// ratio is over the accepted ones. Updates of 10 features (20 dof accepted,
// ρ = 1) and 1 rejected feature of NIS 1000 each: 100 updates in the 1 s
// window judge 1100 features, 100 rejected against a bound of
// binomialQuantile(1100, 0.05, 0.999) = 79, so `degraded` with the gated-out
// cause, first when the window's rejected count exceeds its bound: at update
// 31 (32 rejected of 352, bound 31).
TEST(HealthMonitorStage, GatedOutFeaturesAreDegradedNeverDiverged) {
  ASSERT_EQ(binomialQuantile(1100, 0.05, 0.999), 79);
  HealthMonitor monitor(healthOptions());
  std::vector<Estimate> out;
  int first_degraded = -1;
  for (int k = 0; k < 300; ++k) {
    Estimate e = update(k, 20.0, 20, 10);
    e.innovation.rejected = 1;
    e.innovation.nis += 1000.0;
    e.innovation.dof += 2;
    monitor.process(e, out);
    if (first_degraded < 0 && monitor.verdict().code != io::EstimateStatus::Code::kOk) first_degraded = k;
  }
  EXPECT_EQ(monitor.verdict().code, io::EstimateStatus::Code::kDegraded);
  EXPECT_NE(monitor.verdict().cause.find("gated out"), std::string::npos) << monitor.verdict().cause;
  long expected = -1;
  for (int k = 0; k < 300 && expected < 0; ++k)
    if (k + 1 > binomialQuantile(11L * (k + 1), 0.05, 0.999)) expected = k;
  EXPECT_EQ(expected, 31);
  EXPECT_EQ(first_degraded, expected);
  EXPECT_EQ(monitor.verdict().t_ns, static_cast<TimeNs>(expected) * 10'000'000);

  // One rejected feature in 100 updates of 10: within a consistent filter's share.
  HealthMonitor calm(healthOptions());
  for (int k = 0; k < 300; ++k) {
    Estimate e = update(k, 20.0, 20, 10);
    e.innovation.rejected = k % 100 == 0 ? 1 : 0;
    calm.process(e, out);
  }
  EXPECT_EQ(calm.verdict().code, io::EstimateStatus::Code::kOk);
}

// health.txt keeps the accepted part of the innovations; a file from before
// those two columns reads as if every innovation had been accepted.
TEST(HealthMonitorStage, HealthTextRoundTripsAndReadsTheOlderFormat) {
  test::TempDir dir;
  const std::string path = dir.file("health.txt");
  {
    io::HealthWriter w(path);
    w.append(io::HealthRow{1'000'000'000, 30.5, 24, 10, 2, 7, 3, 0.25, 20.25, 20});
    w.close();
  }
  const auto rows = io::readHealthText(path);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].nis_accepted, 20.25);
  EXPECT_EQ(rows[0].dof_accepted, 20);
  EXPECT_EQ(rows[0].rejected, 2);
  const std::string old_path = dir.file("old_health.txt");
  {
    std::FILE* f = std::fopen(old_path.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("# t nis dof accepted rejected slam msckf sigma_p_m\n1.0 30.5 24 10 2 7 3 0.25\n", f);
    std::fclose(f);
  }
  const auto old_rows = io::readHealthText(old_path);
  ASSERT_EQ(old_rows.size(), 1u);
  EXPECT_EQ(old_rows[0].nis_accepted, 30.5);
  EXPECT_EQ(old_rows[0].dof_accepted, 24);
}

TEST(HealthMonitorStage, StarvationAndCovarianceGrowthAreDegraded) {
  HealthMonitor starving(healthOptions());
  std::vector<Estimate> out;
  for (int k = 0; k < 200; ++k) {
    Estimate e = update(k, 0.0, 0, k < 100 ? 5 : 0);  // nothing accepted from 1 s on
    starving.process(e, out);
  }
  EXPECT_EQ(starving.verdict().code, io::EstimateStatus::Code::kDegraded);
  EXPECT_EQ(starving.verdict().t_ns, 1'500'000'000);  // first over 0.5 s after the last accepted at 0.99 s
  EXPECT_NE(starving.verdict().cause.find("no feature accepted"), std::string::npos);

  HealthMonitor growing(healthOptions());
  for (int k = 0; k < 100; ++k) {
    Estimate e = update(k, 20.0, 20);
    e.cov_pose_B(1, 1) = 0.01 * k * k * 1e-2;  // σ_y = 0.01 k m: above 0.5 m first at k = 51
    growing.process(e, out);
  }
  EXPECT_EQ(growing.verdict().code, io::EstimateStatus::Code::kDegraded);
  EXPECT_EQ(growing.verdict().t_ns, 510'000'000);

  HealthOptions off = healthOptions();
  off.enabled = false;
  HealthMonitor silent(off);
  for (int k = 0; k < 200; ++k) {
    Estimate e = update(k, 1e6, 20, 0);
    silent.process(e, out);
  }
  EXPECT_EQ(silent.verdict().code, io::EstimateStatus::Code::kOk);
}

}  // namespace
}  // namespace evio::estimator

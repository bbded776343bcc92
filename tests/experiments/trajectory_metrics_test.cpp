#include "evio/experiments/trajectory_metrics.h"

#include <gtest/gtest.h>

#include <numbers>
#include <tuple>

#include "evio/core/error.h"
#include "evio/core/random_stream.h"
#include "evio/core/so3.h"
#include "evio/experiments/metrics_format.h"
#include "support/test_trajectories.h"

namespace evio::experiments {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

EvaluationOptions noAlignment() {
  EvaluationOptions o;
  o.alignment.type = "none";
  return o;
}

TEST(TrajectoryMetrics, ConstantOffsetGivesExactAteAndMpe) {
  // 10 m straight line; the estimate is 0.5 m off everywhere (0.3 in y, 0.4 in z).
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 1.0);
  for (const auto& p : in.groundtruth)
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), p.pose.translation() + Vec3(0, 0.3, 0.4))});
  const Metrics m = evaluateTrajectory(in, noAlignment());
  EXPECT_EQ(m.matched_poses, 1001u);
  EXPECT_NEAR(m.groundtruth_length_m, 10.0, 1e-12);
  EXPECT_NEAR(m.ate.position_m.rmse, 0.5, 1e-12);
  EXPECT_NEAR(m.ate.position_m.mean, 0.5, 1e-12);
  EXPECT_NEAR(m.ate.position_m.median, 0.5, 1e-12);
  EXPECT_NEAR(m.ate.position_m.max, 0.5, 1e-12);
  EXPECT_NEAR(m.paper.mpe_percent, 5.0, 1e-10);  // 100 · 0.5 m / 10 m
  EXPECT_NEAR(m.paper.mre_deg_per_m, 0.0, 1e-12);
  EXPECT_EQ(m.status, "ok");
  EXPECT_NEAR(m.completion, 1.0, 1e-12);
  // posyaw (and se3) absorb a constant offset completely.
  const Metrics aligned = evaluateTrajectory(in, EvaluationOptions{});
  EXPECT_LT(aligned.ate.position_m.max, 1e-9);
  EXPECT_LT(aligned.paper.mpe_percent, 1e-8);
}

TEST(TrajectoryMetrics, ConstantYawErrorGivesExactMyeAndMre) {
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 2.0, so3::exp(Vec3(0.1, -0.2, 0.3)));  // L = 20 m
  const Mat3 Rz = rotationZ(3.0 * kDeg);
  for (const auto& p : in.groundtruth)
    in.estimate.push_back({p.t_ns, Pose(Mat3(Rz * p.pose.rotation()), p.pose.translation())});
  const Metrics m = evaluateTrajectory(in, noAlignment());
  EXPECT_NEAR(m.paper.mean_yaw_deg, 3.0, 1e-9);
  EXPECT_NEAR(m.paper.mye_deg_per_m, 3.0 / 20.0, 1e-10);
  EXPECT_NEAR(m.paper.mre_deg_per_m, 3.0 / 20.0, 1e-10);  // a pure yaw error: angle = yaw
  EXPECT_NEAR(m.ate.rotation_deg.rmse, 3.0, 1e-9);
  EXPECT_NEAR(m.pose_errors[0].gravity_deg, 0.0, 1e-9);
  EXPECT_NEAR(m.pose_errors[0].yaw_deg, 3.0, 1e-9);  // yaw of R̂ R_gtᵀ
}

TEST(TrajectoryMetrics, RpeOfALinearScaleDriftIsExact) {
  // Position error grows linearly with distance: p̂ = (1 + ε) p. For every
  // pair, E's translation is ε·(d_j − d_i) = ε·L, so RPE = 100·ε % exactly.
  const double eps = 0.03;
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 1.0);
  for (const auto& p : in.groundtruth)
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), (1.0 + eps) * p.pose.translation())});
  EvaluationOptions o = noAlignment();
  o.rpe.lengths_percent = {10.0, 50.0};
  o.rpe.lengths_m = {2.0};
  o.rpe.tolerance = 0.001;  // only whole-length pairs (the default 20 % admits shorter ones at the end)
  const Metrics m = evaluateTrajectory(in, o);
  ASSERT_EQ(m.rpe.size(), 3u);
  EXPECT_EQ(m.rpe[0].label, "10pct");
  EXPECT_EQ(m.rpe[1].label, "50pct");
  EXPECT_EQ(m.rpe[2].label, "2m");
  EXPECT_EQ(m.rpe[0].translation_percent.count, 901u);  // starts 0 … 9 m with a 1 m end
  EXPECT_EQ(m.rpe[1].translation_percent.count, 501u);
  EXPECT_EQ(m.rpe[2].translation_percent.count, 801u);
  for (const auto& r : m.rpe) {
    EXPECT_NEAR(r.translation_percent.mean, 100.0 * eps, 1e-8) << r.label;
    EXPECT_NEAR(r.translation_percent.max, 100.0 * eps, 1e-8) << r.label;
    EXPECT_NEAR(r.yaw_deg.max, 0.0, 1e-9) << r.label;
    EXPECT_NEAR(r.gravity_deg.max, 0.0, 1e-9) << r.label;
  }
  EXPECT_NEAR(m.rpe[2].length_m, 2.0, 0.0);
}

TEST(TrajectoryMetrics, RpeOfALinearYawDriftIsExact) {
  // Heading drifts at ω about gravity; over a sub-trajectory of L = 2 m at
  // 1 m/s (2 s) the relative yaw error is ω·2 s, and ω·2 s / L deg/m.
  const double omega_deg_s = 0.5;
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 1.0);
  for (const auto& p : in.groundtruth) {
    const Mat3 drift = rotationZ(omega_deg_s * kDeg * nsToSeconds(p.t_ns));
    in.estimate.push_back({p.t_ns, Pose(Mat3(drift * p.pose.rotation()), p.pose.translation())});
  }
  EvaluationOptions o = noAlignment();
  o.rpe.lengths_percent = {};
  o.rpe.lengths_m = {2.0};
  o.rpe.tolerance = 0.001;
  const Metrics m = evaluateTrajectory(in, o);
  ASSERT_EQ(m.rpe.size(), 1u);
  EXPECT_NEAR(m.rpe[0].yaw_deg.mean, 1.0, 1e-8);
  EXPECT_NEAR(m.rpe[0].yaw_deg.max, 1.0, 1e-8);
  EXPECT_NEAR(m.rpe[0].yaw_deg_per_m, 0.5, 1e-8);
  EXPECT_NEAR(m.rpe[0].gravity_deg.max, 0.0, 1e-9);
}

TEST(TrajectoryMetrics, NeesOfSamplesDrawnFromTheStatedCovarianceMatchesItsDimension) {
  // Errors drawn from N(0, P) with correlated (non-diagonal) blocks; the
  // estimate carries P. E[NEES] = 6 (3 + 3); with N = 20000 poses the mean's
  // standard deviation is √(2·6/N) = 0.0245, so 4σ = 0.1 is the tolerance.
  const Trajectory gt = test::wavyTrajectory(200.0, 0.01);
  Mat3 A_p, A_r;
  A_p << 0.05, 0, 0, 0.02, 0.03, 0, -0.01, 0.01, 0.08;  // P = A Aᵀ
  A_r << 0.01, 0, 0, 0.004, 0.02, 0, 0.0, -0.005, 0.015;
  const Mat3 P_p = A_p * A_p.transpose(), P_r = A_r * A_r.transpose();
  RandomStream rng(42, "nees_test");
  EvaluationInputs in;
  in.groundtruth = gt;
  for (const auto& p : gt) {
    const Vec3 e_p = A_p * Vec3(rng.normal(), rng.normal(), rng.normal());
    const Vec3 e_r = A_r * Vec3(rng.normal(), rng.normal(), rng.normal());
    // local convention: R_gt = R̂ Exp(e_r)  ⇒  R̂ = R_gt Exp(−e_r); p_gt = p̂ + e_p.
    const Pose es(Mat3(p.pose.rotation() * so3::exp(-e_r)), p.pose.translation() - e_p);
    in.estimate.push_back({p.t_ns, es});
    in.covariance.push_back({p.t_ns, es, P_r, P_p});
  }
  const Metrics m = evaluateTrajectory(in, noAlignment());
  ASSERT_TRUE(m.nees.available);
  ASSERT_EQ(m.nees.poses, gt.size());
  EXPECT_NEAR(m.nees.mean_pose, 6.0, 0.1);
  EXPECT_NEAR(m.nees.mean_position, 3.0, 4.0 * std::sqrt(6.0 / 20001.0));
  EXPECT_NEAR(m.nees.mean_orientation, 3.0, 4.0 * std::sqrt(6.0 / 20001.0));
  EXPECT_NEAR(m.nees.share_in_bounds, 0.95, 4.0 * std::sqrt(0.95 * 0.05 / 20001.0));
  // NEES in the estimate's own frame ignores the (here posyaw, window) alignment.
  EvaluationOptions own_frame;
  own_frame.alignment = AlignmentOptions::paper();
  own_frame.nees.use_alignment = false;
  EXPECT_DOUBLE_EQ(evaluateTrajectory(in, own_frame).nees.mean_pose, m.nees.mean_pose);
  // Covariances 4× too large: NEES falls to a quarter.
  for (auto& c : in.covariance) {
    c.cov_position *= 4.0;
    c.cov_orientation *= 4.0;
  }
  EXPECT_NEAR(evaluateTrajectory(in, noAlignment()).nees.mean_pose, 1.5, 0.1);
}

TEST(TrajectoryMetrics, NeesBoundsAreTheChiSquaredQuantiles) {
  const auto [lo, hi] = neesBounds(6, 1);
  EXPECT_NEAR(lo, 1.237344245791203, 1e-9);  // χ²_{0.025}(6)
  EXPECT_NEAR(hi, 14.44937533544792, 1e-9);  // χ²_{0.975}(6)
  const auto [lo50, hi50] = neesBounds(6, 50);
  EXPECT_GT(lo50, 5.0);
  EXPECT_LT(hi50, 7.1);
}

TEST(TrajectoryMetrics, DivergenceBoundAndCompletion) {
  // 20 m at 1 m/s; from 10 s the estimate runs away at 0.5 m/s. The bound at
  // time t is 0.1·t + 1 m; 0.5 (t − 10) + 0.001 > 0.1 t + 1 first at t = 15 s.
  EvaluationInputs in;
  in.groundtruth = test::straightLine(20.0, 0.01, 1.0);
  for (const auto& p : in.groundtruth) {
    const double t = nsToSeconds(p.t_ns);
    if (p.t_ns > 16 * kNsPerSecond && p.t_ns < 18 * kNsPerSecond) continue;  // a gap after the divergence
    const double off = t > 10.0 ? 0.5 * (t - 10.0) + 0.001 : 0.0;
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), p.pose.translation() + Vec3(0, off, 0))});
  }
  const Metrics m = evaluateTrajectory(in, noAlignment());
  EXPECT_EQ(m.status, "diverged");
  EXPECT_TRUE(m.divergence.diverged);
  EXPECT_NEAR(m.divergence.time_s, 15.0, 1e-9);
  EXPECT_NEAR(m.completion, 15.0 / 20.0, 1e-9);
  // The estimator's own report wins when earlier.
  io::EstimateStatus status;
  status.code = io::EstimateStatus::Code::kDiverged;
  status.t_ns = secondsToNs(12.0);
  status.cause = "velocity above bound";
  in.status = status;
  const Metrics s = evaluateTrajectory(in, noAlignment());
  EXPECT_NEAR(s.divergence.time_s, 12.0, 1e-12);
  EXPECT_NE(s.cause.find("velocity above bound"), std::string::npos);
  EXPECT_NEAR(s.completion, 12.0 / 20.0, 1e-9);
  EXPECT_EQ(s.estimator_status, "diverged");
  status.code = io::EstimateStatus::Code::kFailed;
  in.status = status;
  EXPECT_EQ(evaluateTrajectory(in, noAlignment()).status, "failed");
}

TEST(TrajectoryMetrics, PaperScoringJudgesDivergenceInTheFrameTheFilterStartedIn) {
  // 10 m at 1 m/s; the estimate starts on the truth and from 4.7 s runs away
  // sideways at 3 m/s: unaligned, 3 (t − 4.7) > 0.1 t + 1 first at
  // t = (1 + 14.1)/2.9 = 5.2069 s. The paper's alignment (posyaw on 3 … 8 s)
  // fits the runaway part and drags the start away, so on aligned errors the
  // run "diverges" from its first poses.
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 1.0);
  for (const auto& p : in.groundtruth) {
    const double t = nsToSeconds(p.t_ns);
    const double off = t > 4.7 ? 3.0 * (t - 4.7) : 0.0;
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), p.pose.translation() + Vec3(0, off, 0))});
  }
  EvaluationOptions aligned = EvaluationOptions::paper();
  aligned.divergence.use_alignment = true;
  const Metrics a = evaluateTrajectory(in, aligned);
  ASSERT_TRUE(a.divergence.diverged);
  EXPECT_LT(a.divergence.time_s, 1.0);
  const Metrics m = evaluateTrajectory(in, EvaluationOptions::paper());
  ASSERT_TRUE(m.divergence.diverged);
  EXPECT_NEAR(m.divergence.time_s, 15.1 / 2.9, 0.011);  // poses every 10 ms
  EXPECT_NEAR(m.completion, m.divergence.time_s / 10.0, 0.002);
  EXPECT_DOUBLE_EQ(m.paper.mpe_percent, a.paper.mpe_percent);  // MPE keeps the paper's alignment
}

TEST(TrajectoryMetrics, CompletionSkipsGapsAndDriftIsPerMinute) {
  EvaluationInputs in;
  in.groundtruth = test::straightLine(120.0, 0.1, 0.0);  // a hover: L_gt = 0
  for (const auto& p : in.groundtruth) {
    const double t = nsToSeconds(p.t_ns);
    if (p.t_ns > 30 * kNsPerSecond && p.t_ns < 60 * kNsPerSecond) continue;  // 30 s without output
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), Vec3(0.005 * t, 0, 0))});  // 0.3 m/min
  }
  const Metrics m = evaluateTrajectory(in, noAlignment());
  EXPECT_NEAR(m.completion, 0.75, 1e-9);
  EXPECT_TRUE(std::isnan(m.paper.mpe_percent));  // L_gt = 0: not a number, not infinity
  EXPECT_EQ(m.status, "ok");
  EXPECT_NEAR(m.drift.final_position_m, 0.005 * 119.5, 1e-9);  // mean over the last 1 s (119 … 120 s)
  EXPECT_NEAR(m.drift.position_m_per_min, 0.005 * 119.5 / 2.0, 1e-9);
}

TEST(TrajectoryMetrics, RealTimeFactorOnTheGrid) {
  EvaluationInputs in;
  in.groundtruth = test::straightLine(10.0, 0.01, 1.0);
  in.estimate = in.groundtruth;
  std::vector<io::TimingSample> timing;
  double processing = 0.0;
  for (int k = 0; k <= 90; ++k) {  // from 1 s to 10 s every 0.1 s
    const double t = 1.0 + 0.1 * k;
    timing.push_back({secondsToNs(t), processing, 100'000 * k, std::nullopt});  // 1e6 events/s; 3 columns
    processing += t < 5.0 ? 0.05 : 0.2;  // RTF 0.5, then 2.0
  }
  in.timing = timing;
  const Metrics m = evaluateTrajectory(in, EvaluationOptions{});
  ASSERT_TRUE(m.rtf.available);
  EXPECT_EQ(m.rtf.samples.size(), 45u);
  EXPECT_NEAR(m.rtf.samples.front().rtf, 0.5, 1e-9);
  EXPECT_NEAR(m.rtf.samples.back().rtf, 2.0, 1e-9);
  EXPECT_NEAR(m.rtf.max, 2.0, 1e-9);
  EXPECT_NEAR(m.rtf.median, 2.0, 1e-9);  // 20 intervals at 0.5, 25 at 2.0
  EXPECT_NEAR(m.rtf.samples[3].event_rate_hz, 1e6, 1e-3);
  EXPECT_NEAR(m.rtf.overall, (20 * 0.1 + 25 * 0.4) / 9.0, 1e-9);
}

// The features column of timing.txt in metrics_rtf.csv (real_time_factor.h):
// F_m is the mean of the rows inside the interval, or the count at its end
// when no row falls inside; RTF per feature = RTF_m / F_m, empty for F_m = 0.
// On a 0.25 s grid with rows every 0.125 s, processing times in multiples of
// 1/16 s and the one interpolated grid point halfway between two rows, every
// value below is exact in binary, so the text is compared whole.
TEST(TrajectoryMetrics, RealTimeFactorPerTrackedFeature) {
  EvaluationInputs in;
  in.groundtruth = test::straightLine(3.0, 0.01, 1.0);
  in.estimate = in.groundtruth;
  // t [s], processing [s], events, features; no row between 1.75 and 2.25 s.
  const std::vector<std::tuple<double, double, std::int64_t, std::int64_t>> rows = {
      {1.0, 0.0, 0, 0},        {1.125, 0.125, 1000, 0},   {1.25, 0.25, 2000, 0},  {1.375, 0.375, 3000, 10},
      {1.5, 0.5, 4000, 30},    {1.625, 0.5625, 5000, 40}, {1.75, 0.625, 6000, 40}, {2.25, 0.875, 10000, 50}};
  std::vector<io::TimingSample> timing;
  for (const auto& [t, p, events, features] : rows) timing.push_back({secondsToNs(t), p, events, features});
  in.timing = timing;
  EvaluationOptions options;
  options.rtf_grid_s = 0.25;
  const Metrics m = evaluateTrajectory(in, options);
  ASSERT_TRUE(m.rtf.features_known);
  EXPECT_EQ(rtfCsv(m),
            "t_s,rtf,event_rate_hz,features,rtf_per_feature\n"
            "1,1,8000,0,\n"              // rows 1.125 and 1.25: no feature, no RTF per feature
            "1.25,1,8000,20,0.05\n"      // rows 1.375 and 1.5: mean of 10 and 30
            "1.5,0.5,8000,40,0.0125\n"   // rows 1.625 and 1.75
            "1.75,0.5,8000,40,0.0125\n"  // no row inside: the count at 2.0 s (row 1.75); P and N halfway
            "2,0.5,8000,50,0.01\n");     // row 2.25
  EXPECT_EQ(m.rtf.median_features, 40.0);        // of 0, 20, 40, 40, 50
  EXPECT_EQ(m.rtf.median_per_feature, 0.0125);   // of the four intervals with features
  const JsonValue j = metricsJson(m, options, {});
  EXPECT_EQ(j.at("rtf.median_per_feature")->asDouble(), 0.0125);
  EXPECT_EQ(j.at("rtf.median_features")->asDouble(), 40.0);
  EXPECT_NE(metricsTable(m).find("RTF per feature   median 0.0125 (median 40.0 features tracked)"), std::string::npos)
      << metricsTable(m);

  // A timing.txt from before the column: the RTF series as before, nothing invented.
  for (io::TimingSample& s : timing) s.features.reset();
  in.timing = timing;
  const Metrics old = evaluateTrajectory(in, options);
  EXPECT_FALSE(old.rtf.features_known);
  EXPECT_EQ(rtfCsv(old), "t_s,rtf,event_rate_hz\n1,1,8000\n1.25,1,8000\n1.5,0.5,8000\n1.75,0.5,8000\n2,0.5,8000\n");
  const JsonValue j_old = metricsJson(old, options, {});
  EXPECT_EQ(j_old.at("rtf.median_per_feature"), nullptr);
  EXPECT_EQ(j_old.at("rtf.median_features"), nullptr);
  EXPECT_EQ(metricsTable(old).find("per feature"), std::string::npos);
}

TEST(TrajectoryMetrics, AssociationInterpolatesAndRefusesTooFewMatches) {
  const Trajectory gt = test::straightLine(10.0, 0.1, 1.0);  // 10 Hz
  Trajectory es;
  for (int k = 0; k < 100; ++k) es.push_back({secondsToNs(0.05 + 0.1 * k), Pose()});
  Pose p;
  ASSERT_TRUE(interpolatePose(gt, secondsToNs(3.05), secondsToNs(0.06), &p));
  EXPECT_NEAR(p.translation().x(), 3.05, 1e-12);
  EXPECT_FALSE(interpolatePose(gt, secondsToNs(3.05), secondsToNs(0.04), &p));  // nearest is 50 ms away
  EXPECT_FALSE(interpolatePose(gt, secondsToNs(10.5), secondsToNs(0.1), &p));   // after the end
  AssociationOptions o;
  o.max_time_difference_s = 0.06;
  EXPECT_EQ(associate(es, gt, o).poses.size(), 100u);
  o.time_offset_s = 5.0;  // half the estimate now lies after the ground truth
  EXPECT_EQ(associate(es, gt, o).poses.size(), 51u);  // 0.05 … 4.95 s, and 5.05 s: 50 ms after the end
  o.min_matched_share = 0.8;
  try {
    associate(es, gt, o);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("only 51 of 100"), std::string::npos) << e.what();
  }
}

TEST(TrajectoryMetrics, JsonAndCsvCarryEveryNumberWithItsAlignment) {
  EvaluationInputs in;
  in.groundtruth = test::wavyTrajectory(12.0);
  for (const auto& p : in.groundtruth)
    in.estimate.push_back({p.t_ns, Pose(p.pose.quaternion(), p.pose.translation() + Vec3(0.1, 0, 0))});
  EvaluationOptions o;
  o.alignment = AlignmentOptions::paper();
  const Metrics m = evaluateTrajectory(in, o);
  const JsonValue j = metricsJson(m, o, {"es.txt", "gt.txt", "", "", ""});
  const JsonValue back = parseJson(j.dump(), "metrics.json");
  EXPECT_EQ(back.dump(), j.dump());
  ASSERT_NE(back.at("paper.mpe_percent"), nullptr);
  EXPECT_DOUBLE_EQ(back.at("paper.mpe_percent")->asDouble(), m.paper.mpe_percent);
  for (const char* group : {"paper", "ate", "drift", "rpe", "divergence", "completion"})
    EXPECT_EQ(back.at(std::string(group) + ".alignment")->text(), "posyaw on t0+3..8 s (501 poses)") << group;
  EXPECT_EQ(back.at("alignment.type")->text(), "posyaw");
  EXPECT_TRUE(back.at("inputs.covariance")->isNull());
  const std::string csv = metricsCsv(j);
  const auto newline = csv.find('\n');
  const std::string header = csv.substr(0, newline), row = csv.substr(newline + 1);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','), std::count(row.begin(), row.end(), ','));
  EXPECT_NE(header.find("ate.position_m.rmse"), std::string::npos);
  EXPECT_EQ(header.find("inputs."), std::string::npos);
  const std::string table = metricsTable(m);
  EXPECT_NE(table.find("posyaw on t0+3..8 s"), std::string::npos);
  const std::string poses = poseErrorsCsv(m);
  EXPECT_EQ(std::count(poses.begin(), poses.end(), '\n'), 1 + 1201);
}

}  // namespace
}  // namespace evio::experiments

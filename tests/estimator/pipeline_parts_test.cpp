// Pieces of the estimator pipelines: options (YAML, overrides, method
// defaults), ground-truth initialisation, tracks input, the event-camera pose
// covariance, the sequence reader's ordering.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "evio/core/io/config.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/so3.h"
#include "evio/estimator/pipeline/estimate_writer.h"
#include "evio/estimator/pipeline/groundtruth_init.h"
#include "evio/estimator/pipeline/pipeline_options.h"
#include "evio/estimator/pipeline/sequence_reader.h"
#include "evio/estimator/pipeline/tracks_input.h"
#include "numeric_jacobian.h"
#include "temp_dir.h"

namespace evio::estimator {
namespace {

// --- options -----------------------------------------------------------------------------

TEST(PipelineOptions, DefaultsRoundTripThroughYaml) {
  for (const char* method : {"eklt-vio", "klt-vio", "tracks"}) {
    const PipelineOptions a = PipelineOptions::forMethod(method);
    a.validate();
    PipelineOptions b;
    config::fill(config::loadString(config::toYaml(a)), "", b);
    EXPECT_TRUE(config::equal(a, b)) << method;
  }
}

TEST(PipelineOptions, MethodDefaults) {
  EXPECT_EQ(PipelineOptions::forMethod("eklt-vio").frontend.tracker, "eklt");
  EXPECT_EQ(PipelineOptions::forMethod("eklt-vio").sync.trigger, "events");
  EXPECT_EQ(PipelineOptions::forMethod("klt-vio").frontend.tracker, "klt");
  EXPECT_EQ(PipelineOptions::forMethod("klt-vio").sync.trigger, "track_time");
  EXPECT_THROW(PipelineOptions::forMethod("orb-slam"), Error);
}

TEST(PipelineOptions, NestedOverridesReachEverySection) {
  config::Document doc = config::loadString("{}");
  for (const char* o : {"sync.n_e=1234", "backend.max_slam_features=7", "frontend.eklt.patch_size_px=17",
                        "init.mode=static", "calibration.T_B_C=[1,0,0,0.1, 0,1,0,0, 0,0,1,0, 0,0,0,1]",
                        "tracks.noise_px=0.5", "output.imu_state=false"})
    config::applyOverride(doc, o);
  PipelineOptions o = PipelineOptions::forMethod("eklt-vio");
  config::fill(doc, "", o);
  EXPECT_EQ(o.sync.n_e, 1234);
  EXPECT_EQ(o.backend.max_slam_features, 7);
  EXPECT_EQ(o.frontend.eklt.patch_size_px, 17);
  EXPECT_EQ(o.init.mode, "static");
  EXPECT_DOUBLE_EQ(o.calibration.T_B_C(0, 3), 0.1);
  EXPECT_DOUBLE_EQ(o.tracks.noise_px, 0.5);
  EXPECT_FALSE(o.output.imu_state);
}

TEST(PipelineOptions, UnknownKeyAndBadValuesNameTheField) {
  const auto fails = [](const std::string& yaml, const std::string& needle) {
    PipelineOptions o = PipelineOptions::forMethod("klt-vio");
    try {
      config::fill(config::loadString(yaml, "cfg.yaml"), "", o);
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      return;
    }
    ADD_FAILURE() << "no error for " << yaml;
  };
  fails("backend:\n  n_slam: 3\n", "n_slam");
  fails("frontend:\n  tracker: eklt\n", "frontend.tracker");  // klt-vio needs klt
  fails("init:\n  mode: magic\n", "init.mode");
  fails("calibration:\n  T_B_C: [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n", "calibration.T_B_C");
  fails("method: vins\n", "method");
  fails("tracks:\n  noise_px: -1\n", "tracks.noise_px");
}

// --- ground-truth initialisation ------------------------------------------------------------

/// Camera trajectory of a body moving with constant velocity v and constant
/// rate ω (about z of W) with the camera at T_B_C: sampled every 10 ms.
Trajectory constantMotion(const Vec3& v, double omega, const Pose& T_B_C, Pose* T_W_B_at_1s) {
  Trajectory out;
  for (int k = 0; k <= 200; ++k) {
    const double t = 0.01 * k;
    const Pose T_W_B(so3::expQuat(Vec3(0, 0, omega * t)), Vec3(1, 2, 3) + v * t);
    if (k == 100) *T_W_B_at_1s = T_W_B;
    out.push_back(StampedPose{secondsToNs(t), T_W_B * T_B_C});
  }
  return out;
}

TEST(GroundTruthInit, PoseAndVelocityOfTheBodyFromTheCameraTrajectory) {
  const Pose T_B_C(so3::expQuat(Vec3(0.3, -1.2, 0.4)), Vec3(0.05, -0.02, 0.1));
  const Vec3 v(0.4, -0.2, 0.1);
  Pose T_W_B_1;
  // Pure translation: interpolation and central difference are exact.
  const Trajectory gt = constantMotion(v, 0.0, T_B_C, &T_W_B_1);
  const ImuState x = initialStateFromTrajectory(gt, secondsToNs(1.0), T_B_C, 0.01, 2500);
  EXPECT_EQ(x.t_ns, secondsToNs(1.0) + 2500);  // IMU clock
  EXPECT_LT((x.p_W_B - T_W_B_1.translation()).norm(), 1e-12);
  EXPECT_LT(angleBetween(x.q_W_B, T_W_B_1.quaternion()), 1e-9);
  EXPECT_LT((x.v_W - v).norm(), 1e-9);
  EXPECT_EQ(x.b_g, Vec3::Zero());
  EXPECT_EQ(x.b_a, Vec3::Zero());
  // Between samples (t = 1.005 s): position and rotation interpolate exactly for this motion.
  const ImuState y = initialStateFromTrajectory(gt, secondsToNs(1.005), T_B_C, 0.01);
  EXPECT_LT((y.p_W_B - (T_W_B_1.translation() + 0.005 * v)).norm(), 1e-12);
}

TEST(GroundTruthInit, RotatingBodyVelocityWithinTheDifferenceError) {
  const Pose T_B_C(so3::expQuat(Vec3(0.3, -1.2, 0.4)), Vec3(0.05, -0.02, 0.1));
  const Vec3 v(0.4, -0.2, 0.1);
  const double omega = 1.5;  // rad/s
  Pose T_W_B_1;
  const Trajectory gt = constantMotion(v, omega, T_B_C, &T_W_B_1);
  const ImuState x = initialStateFromTrajectory(gt, secondsToNs(1.0), T_B_C, 0.01);
  EXPECT_LT((x.p_W_B - T_W_B_1.translation()).norm(), 1e-12);
  EXPECT_LT(angleBetween(x.q_W_B, T_W_B_1.quaternion()), 1e-9);
  // The body origin moves with v exactly (the rotation is about it).
  EXPECT_LT((x.v_W - v).norm(), 1e-9);
}

// perturbInitialState draws the error in the backend's error-state
// convention: over 20 000 draws the sample mean is within 4 standard errors
// of zero and each of the 15 sample standard deviations within 3 % of its σ
// (the standard error of a sample σ is σ/√(2n) = 0.5 %); cross-correlations
// below 0.03 (standard error 1/√n = 0.007). σ = 0 leaves a block exact.
TEST(GroundTruthInit, PerturbationIsADrawOfTheInitialCovariance) {
  ImuState x;
  x.p_W_B = Vec3(1, 2, 3);
  x.v_W = Vec3(0.1, -0.2, 0.3);
  x.q_W_B = so3::expQuat(Vec3(0.3, -0.5, 1.2));
  x.b_g = Vec3(0.01, 0.0, -0.01);
  const InitialErrorSigmas sigmas{0.0, 0.05, 3.0 * M_PI / 180.0, 6.0 * M_PI / 180.0, 0.3};
  const Eigen::Matrix<double, 15, 1> sigma =
      (Eigen::Matrix<double, 15, 1>() << Vec3::Constant(sigmas.p_m), Vec3::Constant(sigmas.v_mps),
       Vec3::Constant(sigmas.theta_rad), Vec3::Constant(sigmas.bg_radps), Vec3::Constant(sigmas.ba_mps2))
          .finished();
  constexpr int kDraws = 20000;
  RandomStream rng(7, "initial_state");
  Eigen::Matrix<double, 15, 15> sum_outer = Eigen::Matrix<double, 15, 15>::Zero();
  Eigen::Matrix<double, 15, 1> sum = Eigen::Matrix<double, 15, 1>::Zero();
  for (int i = 0; i < kDraws; ++i) {
    const ImuState y = perturbInitialState(x, sigmas, rng);
    Eigen::Matrix<double, 15, 1> e;
    e << y.p_W_B - x.p_W_B, y.v_W - x.v_W, so3::log(x.q_W_B.conjugate() * y.q_W_B), y.b_g - x.b_g,
        y.b_a - x.b_a;
    ASSERT_TRUE(e.head<3>().isZero(0.0));
    sum += e;
    sum_outer += e * e.transpose();
  }
  for (int k = 3; k < 15; ++k) {
    const double mean = sum(k) / kDraws;
    const double sd = std::sqrt(sum_outer(k, k) / kDraws - mean * mean);
    EXPECT_LT(std::abs(mean), 4.0 * sigma(k) / std::sqrt(kDraws)) << k;
    EXPECT_NEAR(sd / sigma(k), 1.0, 0.03) << k;
    for (int l = 3; l < k; ++l)
      EXPECT_LT(std::abs(sum_outer(k, l) / kDraws) / (sigma(k) * sigma(l)), 0.03) << k << "," << l;
  }
  // The draw is exactly the documented one: p, v, θ (right perturbation
  // q · Exp(δθ)), b_g, b_a, three normals each, in that order.
  {
    RandomStream drawn(5, "initial_state"), replay(5, "initial_state");
    const ImuState y = perturbInitialState(x, sigmas, drawn);
    Eigen::Matrix<double, 15, 1> n;
    for (int k = 0; k < 15; ++k) n(k) = replay.normal();
    EXPECT_TRUE(y.p_W_B == x.p_W_B + Vec3(n(0), n(1), n(2)) * sigmas.p_m);
    EXPECT_TRUE(y.v_W == x.v_W + Vec3(n(3), n(4), n(5)) * sigmas.v_mps);
    EXPECT_TRUE(y.q_W_B.coeffs() ==
                (x.q_W_B * so3::expQuat(Vec3(n(6), n(7), n(8)) * sigmas.theta_rad)).normalized().coeffs());
    EXPECT_TRUE(y.b_g == x.b_g + Vec3(n(9), n(10), n(11)) * sigmas.bg_radps);
    EXPECT_TRUE(y.b_a == x.b_a + Vec3(n(12), n(13), n(14)) * sigmas.ba_mps2);
  }
  // The same seed gives the same state.
  RandomStream a(3, "initial_state"), b(3, "initial_state");
  const ImuState ya = perturbInitialState(x, sigmas, a), yb = perturbInitialState(x, sigmas, b);
  EXPECT_TRUE(ya.p_W_B == yb.p_W_B && ya.v_W == yb.v_W && ya.q_W_B.coeffs() == yb.q_W_B.coeffs() &&
              ya.b_g == yb.b_g && ya.b_a == yb.b_a);
}

TEST(GroundTruthInit, OutsideTheSpanIsAnError) {
  Pose unused;
  const Trajectory gt = constantMotion(Vec3::Zero(), 0.0, Pose(), &unused);
  EXPECT_THROW(interpolatePose(gt, secondsToNs(2.5)), Error);
  EXPECT_THROW(interpolatePose(Trajectory{}, 0), Error);
  // At the very start the window is one-sided but valid.
  EXPECT_NO_THROW(initialStateFromTrajectory(gt, 0, Pose(), 0.01));
}

// --- tracks input ----------------------------------------------------------------------------

std::vector<io::TrackSample> lineTracks(int n_tracks, double rate_hz, double duration_s) {
  std::vector<io::TrackSample> out;
  const TimeNs dt = secondsToNs(1.0 / rate_hz);
  for (TimeNs t = 0; t <= secondsToNs(duration_s); t += dt)
    for (int i = 0; i < n_tracks; ++i)
      out.push_back(io::TrackSample{i, t, Vec2(10.0 * i + 100.0 * nsToSeconds(t), 5.0 * i)});
  return out;
}

TEST(TracksInput, FixedRateSetsHoldTheExactSamplesAtTheirTimes) {
  TracksInputOptions o;
  o.rate_hz = 20.0;
  TracksInput input(lineTracks(3, 200.0, 1.0), o, 1);
  std::vector<MeasurementSet> sets;
  input.advanceTo(secondsToNs(1.0), sets);
  ASSERT_EQ(sets.size(), 20u);  // 0.05 … 1.0 s
  for (std::size_t k = 0; k < sets.size(); ++k) {
    EXPECT_EQ(sets[k].t_ns, secondsToNs(0.05 * static_cast<double>(k + 1)));
    ASSERT_EQ(sets[k].features.size(), 3u);
    for (const auto& f : sets[k].features)
      EXPECT_NEAR(f.uv.x(), 10.0 * static_cast<double>(f.id) + 100.0 * nsToSeconds(sets[k].t_ns), 1e-9);
    EXPECT_EQ(sets[k].features[0].has_previous, k > 0);
  }
}

TEST(TracksInput, AdvancesIncrementallyAndEndsTracks) {
  TracksInputOptions o;
  o.rate_hz = 0.0;  // one set per file time
  auto samples = lineTracks(2, 100.0, 0.5);
  std::erase_if(samples, [](const io::TrackSample& s) { return s.id == 1 && s.t_ns > secondsToNs(0.2); });
  TracksInput input(samples, o, 1);
  std::vector<MeasurementSet> sets;
  input.advanceTo(secondsToNs(0.1), sets);
  EXPECT_EQ(sets.size(), 11u);  // 0, 0.01, …, 0.1
  input.advanceTo(secondsToNs(0.5), sets);
  ASSERT_EQ(sets.size(), 51u);
  EXPECT_EQ(sets[20].features.size(), 2u);  // 0.2 s: both
  EXPECT_EQ(sets[21].features.size(), 1u);  // track 1 ended
}

TEST(TracksInput, GapsSplitTracksUnderNewIds) {
  TracksInputOptions o;
  o.rate_hz = 0.0;
  o.max_gap_s = 0.05;
  auto samples = lineTracks(2, 100.0, 1.0);
  // Track 0 vanishes for 0.3 s.
  std::erase_if(samples, [](const io::TrackSample& s) {
    return s.id == 0 && s.t_ns > secondsToNs(0.3) && s.t_ns < secondsToNs(0.6);
  });
  TracksInput input(samples, o, 1);
  EXPECT_EQ(input.numSplits(), 1u);
  EXPECT_EQ(input.numTracks(), 3u);
  std::vector<MeasurementSet> sets;
  input.advanceTo(secondsToNs(1.0), sets);
  const auto ids = [](const MeasurementSet& s) {
    std::vector<FeatureId> v;
    for (const auto& f : s.features) v.push_back(f.id);
    return v;
  };
  EXPECT_EQ(ids(sets[10]), (std::vector<FeatureId>{0, 1}));
  EXPECT_EQ(ids(sets[45]), (std::vector<FeatureId>{1}));
  EXPECT_EQ(ids(sets[70]), (std::vector<FeatureId>{1, 2}));  // track 0 resumed as id 2
  EXPECT_FALSE(sets[60].features.back().has_previous);
}

TEST(TracksInput, NoiseHasTheRequestedSigma) {
  TracksInputOptions o;
  o.rate_hz = 0.0;
  o.noise_px = 0.7;
  const auto clean = lineTracks(50, 100.0, 2.0);
  TracksInput input(clean, o, 3);
  std::vector<MeasurementSet> sets;
  input.advanceTo(secondsToNs(2.0), sets);
  double sum2 = 0.0, sum = 0.0;
  std::size_t n = 0;
  for (const auto& s : sets)
    for (const auto& f : s.features) {
      const double e = f.uv.x() - (10.0 * static_cast<double>(f.id) + 100.0 * nsToSeconds(s.t_ns));
      sum += e;
      sum2 += e * e;
      ++n;
    }
  ASSERT_EQ(n, clean.size());
  const double mean = sum / static_cast<double>(n), sigma = std::sqrt(sum2 / static_cast<double>(n) - mean * mean);
  // n = 10050: the sample σ has a relative standard error of 1/√(2n) ≈ 0.7 %; allow 5 %.
  EXPECT_NEAR(sigma, 0.7, 0.035);
  EXPECT_NEAR(mean, 0.0, 0.03);
}

// --- event-camera pose covariance -----------------------------------------------------------

TEST(EstimateWriter, CameraPoseCovarianceMatchesTheNumericJacobian) {
  const Quat q_W_B = so3::expQuat(Vec3(0.2, -0.4, 1.1));
  const Vec3 p_W_B(1.0, -2.0, 0.5);
  const Pose T_B_E(so3::expQuat(Vec3(-1.0, 0.3, 0.2)), Vec3(0.04, -0.03, 0.12));
  const Pose T_W_E0 = Pose(q_W_B, p_W_B) * T_B_E;
  // Error of the camera pose for an IMU error [δp; δθ] (δp in W, R ← R Exp(δθ)).
  const auto f = [&](const Vec6& d) -> Vec6 {
    const Pose T_W_B(q_W_B * so3::expQuat(Vec3(d.tail<3>())), p_W_B + d.head<3>());
    const Pose T_W_E = T_W_B * T_B_E;
    Vec6 e;
    e.head<3>() = T_W_E.translation() - T_W_E0.translation();
    e.tail<3>() = so3::log(Quat(T_W_E0.quaternion().conjugate() * T_W_E.quaternion()));
    return e;
  };
  const Mat6 J = test::numericJacobian<6, 6>(f, Vec6::Zero());
  Eigen::Matrix<double, 15, 15> P = Eigen::Matrix<double, 15, 15>::Zero();
  Eigen::Matrix<double, 15, 15> A = Eigen::Matrix<double, 15, 15>::Random();
  P = A * A.transpose() + Eigen::Matrix<double, 15, 15>::Identity();
  Mat6 P_pt;  // the [δp; δθ] block
  P_pt << P.block<3, 3>(0, 0), P.block<3, 3>(0, 6), P.block<3, 3>(6, 0), P.block<3, 3>(6, 6);
  const Mat6 expected = J * P_pt * J.transpose();
  const Mat6 got = cameraPoseCovariance(P, q_W_B, T_B_E);
  EXPECT_LT((got - expected).cwiseAbs().maxCoeff(), 1e-6 * expected.cwiseAbs().maxCoeff());
}

// --- sequence reader ---------------------------------------------------------------------------

TEST(SequenceReader, MergesStreamsInTimeOrderOnTheCameraClock) {
  test::TempDir dir;
  const std::string folder = dir.path().string();
  // IMU at 0, 10, 20 ms (IMU clock), frames at 5 and 15 ms, events every ms 1..24.
  ImuSamples imu;
  for (int k = 0; k < 3; ++k) imu.push_back(ImuSample{k * 10 * kNsPerMs, Vec3(0, 0, 9.81), Vec3::Zero()});
  io::writeImuText(dir.file("imu.txt"), imu);
  EventArray events;
  for (int k = 1; k < 25; ++k) events.push_back(k * kNsPerMs, 1, 1, true);
  io::writeEventsText(dir.file("events.txt"), events);
  io::ImageFolderWriter frames(folder);
  frames.append(5 * kNsPerMs, cv::Mat(4, 6, CV_8UC1, cv::Scalar(7)));
  frames.append(15 * kNsPerMs, cv::Mat(4, 6, CV_8UC1, cv::Scalar(7)));
  frames.close();
  // Range readings at 5 ms (with the frame: after it), 12 ms (no return) and 26 ms (after the events).
  io::writeRangeText(dir.file("range.txt"), {{5 * kNsPerMs, 7.5, true}, {12 * kNsPerMs, 0.0, false},
                                             {26 * kNsPerMs, 8.25, true}});

  std::vector<io::RangeSample> ranges;
  const auto run = [&](TimeNs offset, bool read_range = false) {
    SequenceReaderOptions o;
    o.max_events_per_chunk = 3;
    o.time_offset_cam_imu_ns = offset;
    o.read_range = read_range;
    SequenceReader reader(folder, o);
    std::string order;
    SequenceItem item;
    TimeNs last = std::numeric_limits<TimeNs>::min();
    while (reader.next(item)) {
      if (item.kind == SequenceItem::Kind::kEvents) {
        EXPECT_LE(item.events.size(), 3u);
        EXPECT_GE(item.events.t().front(), last);
        last = item.events.t().back();
        order += 'e';
      } else {
        EXPECT_GE(item.t_ns, last);
        if (item.kind == SequenceItem::Kind::kFrame) {
          EXPECT_EQ(reader.loadFrame(item.frame_index).cols, 6);
          order += 'F';
        } else if (item.kind == SequenceItem::Kind::kRange) {
          EXPECT_EQ(item.t_ns, item.range.t_ns);
          ranges.push_back(item.range);
          order += 'R';
        } else {
          order += 'I';
        }
        last = item.t_ns;
      }
    }
    EXPECT_DOUBLE_EQ(reader.fraction(), 1.0);
    EXPECT_EQ(reader.eventsRead(), 24u);
    return order;
  };
  // Events 1-4 | F(5) | 5-9 | I(10) | 10-14 | F(15) | 15-19 | I(20) | 20-24.
  EXPECT_EQ(run(0), "IeeFeeIeeFeeIee");
  // With t_imu = t_cam + 2 ms the IMU samples sit at −2, 8 and 18 ms of the camera clock.
  EXPECT_EQ(run(2 * kNsPerMs), "IeeFeIeeeFeIeee");
  // range.txt on the camera clock: 1-4 | F(5) R(5) | 5-9 | I(10) | 10-11 | R(12) | 12-14 | F(15) | … | R(26).
  EXPECT_EQ(run(0, true), "IeeFReeIeReFeeIeeR");
  ASSERT_EQ(ranges.size(), 3u);
  EXPECT_EQ(ranges[0], (io::RangeSample{5 * kNsPerMs, 7.5, true}));
  EXPECT_FALSE(ranges[1].valid);
  EXPECT_EQ(ranges[2], (io::RangeSample{26 * kNsPerMs, 8.25, true}));
}

TEST(SequenceReader, MissingStreamsAreErrors) {
  test::TempDir dir;
  SequenceReaderOptions o;
  EXPECT_THROW(SequenceReader(dir.path().string(), o), Error);  // no events
  o.read_events = false;
  EXPECT_THROW(SequenceReader(dir.path().string(), o), Error);  // no imu.txt
  o.read_imu = false;
  SequenceReader reader(dir.path().string(), o);
  EXPECT_FALSE(reader.hasFrames());
  SequenceItem item;
  EXPECT_FALSE(reader.next(item));
  EXPECT_THROW(SequenceReader(dir.file("nope"), o), Error);
  o.read_range = true;
  try {
    SequenceReader no_range(dir.path().string(), o);
    FAIL() << "a missing range.txt was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("range.txt"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace evio::estimator

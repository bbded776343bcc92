// Backend propagation against exact trajectories (trajectories presets, exact
// IMU from the simulator), static initialisation, and bad input.
#include <gtest/gtest.h>

#include <yaml-cpp/yaml.h>

#include <cstdio>

#include "evio/core/so3.h"
#include "evio/estimator/backend/backend.h"
#include "evio/estimator/backend/static_initializer.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/trajectory_factory.h"
#include "trajectory_presets.h"

namespace evio::estimator {
namespace {

BackendSensors testSensors(double gravity) {
  BackendSensors s{Camera(PinholeCamera(346, 260, Vec4(300, 300, 172.5, 129.5))), Pose(), gravity, ImuSensor{},
                   std::nullopt, 0};
  s.imu.accelerometer_noise_density = 0.004316;
  s.imu.accelerometer_random_walk = 0.0004316;
  s.imu.gyroscope_noise_density = 0.0002;
  s.imu.gyroscope_random_walk = 0.00002;
  s.imu.update_rate = 1000;
  return s;
}

ImuState truthState(const TrajectoryState& x) {
  ImuState s;
  s.t_ns = x.t_ns;
  s.p_W_B = x.T_W_B.translation();
  s.v_W = x.v_W;
  s.q_W_B = x.T_W_B.quaternion();
  return s;
}

class BackendExactPropagation : public ::testing::TestWithParam<std::string> {};

// Exact (noiseless) 1 kHz IMU from the true initial state: after 10 s the
// propagated state follows the true one. Tolerances: position 2 mm, velocity
// 1 mm/s, attitude 1e-4 rad (measured: rotation_only 5.3e-5 rad, the others
// below 7e-6 rad, 0.4 mm, 0.3 mm/s; the integrator is exact for a linearly varying
// rate and specific force; the error is the curvature of both within 1 ms).
TEST_P(BackendExactPropagation, FollowsTheTrueStateFor10s) {
  const auto traj = makeTrajectory(test::trajectoryPresetPath(GetParam() + ".yaml"), {"duration_s=12"});
  ImuSimulator::Options o;
  o.accelerometer_noise_density = o.accelerometer_random_walk = 0.0;
  o.gyroscope_noise_density = o.gyroscope_random_walk = 0.0;
  o.gravity_mps2 = YAML::Load(traj->configYaml())["gravity_mps2"].as<double>();
  ImuSimulator sim(*traj, o, 1);
  BackendOptions bo;
  bo.max_delay_s = 0.0;
  Backend backend(bo, testSensors(o.gravity_mps2));
  backend.initialize(truthState(traj->evaluate(traj->startTime())));
  ImuMeasurement m;
  const TimeNs end = traj->startTime() + 10 * kNsPerSecond;
  double max_p = 0, max_v = 0, max_th = 0;
  while (sim.next(m) && m.sample.t_ns <= end) {
    backend.addImu(m.sample);
    const Estimate e = backend.estimate();
    ASSERT_EQ(e.t_ns, m.sample.t_ns);
    const TrajectoryState x = traj->evaluate(e.t_ns);
    max_p = std::max(max_p, (e.T_W_B.translation() - x.T_W_B.translation()).norm());
    max_v = std::max(max_v, (e.imu.v_W - x.v_W).norm());
    max_th = std::max(max_th, angleBetween(e.T_W_B.quaternion(), x.T_W_B.quaternion()));
  }
  EXPECT_LT(max_p, 2e-3) << GetParam();
  EXPECT_LT(max_v, 1e-3) << GetParam();
  EXPECT_LT(max_th, 1e-4) << GetParam();
  std::printf("%s: max error over 10 s: position %.3g m, velocity %.3g m/s, attitude %.3g rad\n",
              GetParam().c_str(), max_p, max_v, max_th);
  EXPECT_TRUE(backend.status().ok());
  // Covariance grows but stays symmetric positive definite.
  const MatX& P = backend.state().P;
  EXPECT_LT((P - P.transpose()).norm(), 1e-15 * P.norm());
  EXPECT_EQ(Eigen::LLT<MatX>(P).info(), Eigen::Success);
  EXPECT_GT(P(kIdxP, kIdxP), 1e-6);
}

INSTANTIATE_TEST_SUITE_P(Presets, BackendExactPropagation,
                         ::testing::Values("six_dof", "rotation_only", "hover", "circle"));

TEST(BackendStaticInit, RecoversTiltAndGyroBiasFromStillReadings) {
  const Mat3 R_W_B = so3::exp(Vec3(0.2, -0.1, 0.7));
  const Vec3 b_g(0.01, -0.02, 0.005);
  RandomStream rng(4, "still");
  ImuSamples samples;
  for (int k = 0; k < 1000; ++k) {
    ImuSample s;
    s.t_ns = k * kNsPerMs;
    s.acc_B = R_W_B.transpose() * Vec3(0, 0, 3.721) + Vec3(rng.normal(), rng.normal(), rng.normal()) * 0.004;
    s.gyro_B = b_g + Vec3(rng.normal(), rng.normal(), rng.normal()) * 0.0002 * std::sqrt(1000.0);
    samples.push_back(s);
  }
  const auto res = staticInitialize(samples, 3.721, 0.1, 0.02);
  ASSERT_TRUE(res.has_value());
  // Gravity direction within 3σ of the mean's noise (0.004/√1000/3.721 rad), gyro bias likewise.
  const Vec3 up_B_true = R_W_B.transpose().col(2);
  const Vec3 up_B_est = res->state.q_W_B.toRotationMatrix().transpose().col(2);
  EXPECT_LT(std::acos(std::min(1.0, up_B_true.dot(up_B_est))), 3 * 0.004 * std::sqrt(3.0 / 1000) / 3.721 + 1e-9);
  EXPECT_LT((res->state.b_g - b_g).norm(), 3 * 0.0063 * std::sqrt(3.0 / 1000));
  EXPECT_NEAR(so3::log(res->state.q_W_B).z(), 0.0, 0.2);  // yaw set to 0 (up to tilt coupling)

  // The backend, fed a moving IMU, refuses; fed still readings, initialises.
  Backend backend(BackendOptions{}, testSensors(3.721));
  ImuSamples moving = samples;
  for (std::size_t k = 0; k < moving.size(); ++k) moving[k].gyro_B += Vec3(0.5 * std::sin(0.01 * k), 0, 0);
  EXPECT_FALSE(backend.staticInitialize(moving));
  EXPECT_FALSE(backend.initialized());
  EXPECT_TRUE(backend.staticInitialize(samples));
  EXPECT_TRUE(backend.initialized());

  // Automatic static initialisation from the stream.
  Backend automatic(BackendOptions{}, testSensors(3.721));
  automatic.setAutoStaticInitialization(true);
  for (const auto& s : samples) automatic.addImu(s);
  EXPECT_FALSE(automatic.initialized());  // 0.999 s of readings: not yet a full window
  ImuSample more = samples.back();
  more.t_ns += 2 * kNsPerMs;
  automatic.addImu(more);
  EXPECT_TRUE(automatic.initialized());
}

/// A still IMU reading (level body, Earth gravity, no turn) at time t.
ImuSample stillReading(TimeNs t) { return {t, Vec3(0, 0, 9.81), Vec3::Zero()}; }

class BackendBadInput : public ::testing::Test {
 protected:
  BackendBadInput() : backend_(options(), testSensors(9.81)) {
    ImuState s;
    s.t_ns = 0;
    backend_.initialize(s);
  }
  static BackendOptions options() {
    BackendOptions o;
    o.max_delay_s = 0.0;
    return o;
  }
  static ImuSample still(TimeNs t) { return stillReading(t); }
  Backend backend_;
};

TEST_F(BackendBadInput, OutOfOrderImuIsAnError) {
  backend_.addImu(still(10 * kNsPerMs));
  backend_.addImu(still(10 * kNsPerMs));  // duplicate stamp: dropped and counted
  EXPECT_EQ(backend_.stats().imu_duplicates_dropped, 1);
  try {
    backend_.addImu(still(5 * kNsPerMs));
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("older than the previous"), std::string::npos) << e.what();
  }
}

TEST_F(BackendBadInput, OutOfOrderMeasurementSetsAreAnError) {
  for (int k = 1; k <= 100; ++k) backend_.addImu(still(k * kNsPerMs));
  MeasurementSet a;
  a.t_ns = 50 * kNsPerMs;
  backend_.addMeasurementSet(a);
  a.t_ns = 40 * kNsPerMs;
  EXPECT_THROW(backend_.addMeasurementSet(a), Error);
}

TEST_F(BackendBadInput, ImuGapFailsWithTimeAndCauseButNeverThrows) {
  for (int k = 1; k <= 10; ++k) backend_.addImu(still(k * kNsPerMs));
  backend_.addImu(still(10 * kNsPerMs + 100 * kNsPerMs));  // 0.1 s gap: counted, bridged
  EXPECT_EQ(backend_.stats().imu_gaps, 1);
  EXPECT_TRUE(backend_.status().ok());
  backend_.addImu(still(3 * kNsPerSecond));  // ~2.9 s gap: failed
  EXPECT_EQ(backend_.status().code, BackendStatus::Code::kFailed);
  EXPECT_NE(backend_.status().cause.find("IMU gap"), std::string::npos) << backend_.status().cause;
  EXPECT_GT(backend_.status().t_ns, 0);
  backend_.addImu(still(4 * kNsPerSecond));  // ignored from now on
  MeasurementSet set;
  set.t_ns = 4 * kNsPerSecond;
  backend_.addMeasurementSet(set);
  EXPECT_EQ(backend_.status().code, BackendStatus::Code::kFailed);
}

TEST_F(BackendBadInput, OutlierImuReadingsAreReplacedByThePreviousOne) {
  backend_.addImu(still(1 * kNsPerMs));
  ImuSample bad = still(2 * kNsPerMs);
  bad.acc_B = Vec3(0, 0, 1e4);
  backend_.addImu(bad);
  bad.t_ns = 3 * kNsPerMs;
  bad.gyro_B = Vec3(NAN, 0, 0);
  backend_.addImu(bad);
  for (int k = 4; k <= 100; ++k) backend_.addImu(still(k * kNsPerMs));
  EXPECT_EQ(backend_.stats().imu_outliers_replaced, 2);
  EXPECT_TRUE(backend_.status().ok());
  EXPECT_LT(backend_.estimate().imu.v_W.norm(), 1e-12);  // as if still throughout
}

TEST_F(BackendBadInput, BadFeaturePositionsAreCountedNotFatal) {
  for (int k = 1; k <= 50; ++k) backend_.addImu(still(k * kNsPerMs));
  MeasurementSet set;
  set.t_ns = 50 * kNsPerMs;
  set.features.push_back({1, Vec2(NAN, 3.0), Vec2::Zero(), false});
  set.features.push_back({2, Vec2(100.0, 100.0), Vec2::Zero(), false});
  set.features.push_back({2, Vec2(101.0, 100.0), Vec2::Zero(), false});  // duplicate id: ignored
  backend_.addMeasurementSet(set);
  EXPECT_EQ(backend_.stats().features_undistort_failed, 1);
  EXPECT_EQ(backend_.stats().measurement_sets, 1);
  EXPECT_TRUE(backend_.status().ok()) << backend_.status().cause;
  EXPECT_EQ(backend_.takeEstimates().size(), 1u);
}

TEST_F(BackendBadInput, RunawayImuIsReportedAsDivergence) {
  for (int k = 1; k <= 3000; ++k) {
    ImuSample s = still(k * kNsPerMs);
    s.acc_B = Vec3(80.0, 0, 9.81);  // below the outlier bound, but 80 m/s² for 3 s
    backend_.addImu(s);
  }
  EXPECT_EQ(backend_.status().code, BackendStatus::Code::kDiverged);
  EXPECT_NE(backend_.status().cause.find("velocity"), std::string::npos) << backend_.status().cause;
  EXPECT_NEAR(nsToSeconds(backend_.status().t_ns), 1.25, 0.01);  // 100 m/s at 80 m/s²
}

TEST(BackendInput, MeasurementsBeforeInitialisationAreCounted) {
  Backend backend(BackendOptions{}, testSensors(9.81));
  MeasurementSet set;
  set.t_ns = 5;
  backend.addMeasurementSet(set);
  EXPECT_EQ(backend.stats().measurements_before_init, 1);
  EXPECT_FALSE(backend.initialized());
}

TEST(BackendInput, OptionsAreValidatedWithTheFieldName) {
  BackendOptions o;
  o.window_size = 1;
  try {
    Backend b(o, testSensors(9.81));
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("window_size"), std::string::npos);
  }
}

// The covariance tests. A 3 × 3 velocity block with correlations 0.9, 0.9 and
// −0.9 is indefinite (determinant 1 − 3·0.81 − 2·0.729 < 0) although every
// 2 × 2 principal minor is 1 − 0.81 > 0: only the full (Cholesky) test sees it.
Eigen::Matrix<double, 15, 15> withVelocityBlock(const Mat3& block) {
  Eigen::Matrix<double, 15, 15> P = Eigen::Matrix<double, 15, 15>::Identity() * 1e-4;
  P.block<3, 3>(kIdxV, kIdxV) = 0.01 * block;
  return P;
}

Mat3 indefiniteWithPositiveMinors() {
  Mat3 c;
  c << 1.0, 0.9, 0.9, 0.9, 1.0, -0.9, 0.9, -0.9, 1.0;
  return c;
}

BackendStatus statusAfterStillSeconds(const BackendOptions& o, const Eigen::Matrix<double, 15, 15>& P0, double s) {
  Backend backend(o, testSensors(9.81));
  ImuState x;
  x.t_ns = 0;
  backend.initialize(x, P0);
  for (TimeNs t = kNsPerMs; t <= secondsToNs(s); t += kNsPerMs) backend.addImu(stillReading(t));
  return backend.status();
}

TEST(BackendHealth, AnIndefiniteCovarianceIsCaughtByTheFirstFullTestWhateverTheInterval) {
  for (const double interval_s : {0.0, 0.1, 60.0}) {
    BackendOptions o;
    o.max_delay_s = 0.0;
    o.covariance_check_interval_s = interval_s;
    const BackendStatus st = statusAfterStillSeconds(o, withVelocityBlock(indefiniteWithPositiveMinors()), 0.01);
    EXPECT_EQ(st.code, BackendStatus::Code::kDiverged) << interval_s;
    EXPECT_EQ(st.cause, "covariance not positive semi-definite") << interval_s;
    EXPECT_EQ(st.t_ns, kNsPerMs) << interval_s;  // the first item after the start
  }
}

TEST(BackendHealth, ACorrelationAboveOneIsNamedAtTheFirstItem) {
  Mat3 c = Mat3::Identity();
  c(0, 2) = c(2, 0) = 1.001;  // |ρ| > 1 between v_x and v_z
  BackendOptions o;
  o.max_delay_s = 0.0;
  o.covariance_check_interval_s = 60.0;
  const BackendStatus st = statusAfterStillSeconds(o, withVelocityBlock(c), 0.01);
  EXPECT_EQ(st.code, BackendStatus::Code::kDiverged);
  const std::string names = "(variables " + std::to_string(kIdxV) + " and " + std::to_string(kIdxV + 2) + ")";
  EXPECT_NE(st.cause.find(names), std::string::npos) << st.cause;
}

/// The status after `finish()` on a backend started with P0 and given no
/// input: the end-of-input test on P0 exactly (no process noise added).
BackendStatus statusAtFinish(const BackendOptions& o, const Eigen::Matrix<double, 15, 15>& P0) {
  Backend backend(o, testSensors(9.81));
  ImuState x;
  x.t_ns = 0;
  backend.initialize(x, P0);
  backend.finish();
  return backend.status();
}

TEST(BackendHealth, TheEndOfTheInputRunsTheFullTest) {
  BackendOptions o;
  o.covariance_check_interval_s = 60.0;
  const BackendStatus st = statusAtFinish(o, withVelocityBlock(indefiniteWithPositiveMinors()));
  EXPECT_EQ(st.code, BackendStatus::Code::kDiverged);
  EXPECT_EQ(st.cause, "covariance not positive semi-definite");
}

TEST(BackendHealth, ASemiDefiniteCovarianceStaysOk) {
  // Correlation exactly 1 (a clone of the velocity, say) is singular, not
  // indefinite: both the minors and the Cholesky test of P + 1e-9 diag(P)
  // accept it, tested on P0 exactly and after half a second of propagation.
  const Mat3 c = Mat3::Constant(1.0);
  BackendOptions o;
  o.max_delay_s = 0.0;
  EXPECT_TRUE(statusAtFinish(o, withVelocityBlock(c)).ok()) << statusAtFinish(o, withVelocityBlock(c)).cause;
  for (const double interval_s : {0.0, 0.1}) {
    o.covariance_check_interval_s = interval_s;
    const BackendStatus st = statusAfterStillSeconds(o, withVelocityBlock(c), 0.5);
    EXPECT_TRUE(st.ok()) << interval_s << ": " << st.cause;
  }
}

TEST(BackendHealth, ARestartTestsItsCovarianceAtOnce) {
  // A long interval and a healthy first start; the second start's indefinite
  // P0 is caught at its first item, not 60 s after the first start's test.
  BackendOptions o;
  o.max_delay_s = 0.0;
  o.covariance_check_interval_s = 60.0;
  Backend backend(o, testSensors(9.81));
  ImuState x;
  x.t_ns = 0;
  backend.initialize(x, withVelocityBlock(Mat3::Identity()));
  for (TimeNs t = kNsPerMs; t <= 10 * kNsPerMs; t += kNsPerMs) backend.addImu(stillReading(t));
  ASSERT_TRUE(backend.status().ok());
  x.t_ns = 10 * kNsPerMs;
  backend.initialize(x, withVelocityBlock(indefiniteWithPositiveMinors()));
  backend.addImu(stillReading(11 * kNsPerMs));
  EXPECT_EQ(backend.status().code, BackendStatus::Code::kDiverged);
  EXPECT_EQ(backend.status().t_ns, 11 * kNsPerMs);
}

}  // namespace
}  // namespace evio::estimator

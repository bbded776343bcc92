// The optional updates of the backend: laser range finder (scale in hover)
// and zero velocity, on exact ground truth.
#include <gtest/gtest.h>

#include <cstdio>

#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/visual_models.h"
#include "support/backend_scenarios.h"

namespace evio::estimator {
namespace {

// The range finder observes the distance to the terrain along the beam, not
// the altitude in W: one update moves the depths of the three SLAM features
// that define the terrain plane under the beam to agree with it.
TEST(BackendRangeFinder, OneUpdateCorrectsTheTerrainDepth) {
  FilterState s;
  s.imu.p_W_B = Vec3(0.0, 0.0, 10.0);  // B: z up, 10 m above the ground z = 0
  CameraClone c;  // a down-looking camera at the body
  c.id = 1;
  c.p_W_C = c.p_fej = s.imu.p_W_B;
  c.q_W_C = c.q_fej = Quat(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()));
  s.clones.push_back(c);
  const Vec3 ground[3] = {Vec3(1.0, 0.5, 0.0), Vec3(-0.8, 0.9, 0.0), Vec3(0.1, -1.2, 0.0)};
  for (int j = 0; j < 3; ++j) {
    SlamFeature f;
    f.id = j;
    f.anchor_clone_id = 1;
    ASSERT_TRUE(worldToAnchored(c, ground[j], &f.abr));
    f.abr.z() *= 1.25;  // 25 % too near (the truth is 10 m)
    s.features.push_back(f);
  }
  s.P = MatX::Identity(s.dim(), s.dim()) * 1e-8;
  for (int j = 0; j < 3; ++j) s.P(s.featureIndex(j) + 2, s.featureIndex(j) + 2) = 0.05 * 0.05;
  const Pose T_B_L(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()), Vec3::Zero());  // beam down
  auto plane_range = [&T_B_L](const FilterState& x) {
    Eigen::Matrix<double, 1, Eigen::Dynamic> H;
    double r = 0.0;
    EXPECT_TRUE(rangeResidual(x, T_B_L, 10.0, 0.5, &H, &r));
    return std::make_pair(MatX(H), VecX::Constant(1, r));
  };
  const auto [H0, r0] = plane_range(s);
  EXPECT_NEAR(r0(0), 10.0 - 8.0, 1e-9);  // the plane through the features is 8 m away
  ASSERT_TRUE(ekfUpdate(s, H0, r0, 0.02 * 0.02, true));
  const auto [H1, r1] = plane_range(s);
  // Range ∝ 1/ρ: the linearised step is Newton's on 1/ρ and overshoots
  // (2 m → −0.67 m); a second reading, weighed against the now smaller ρ
  // covariance, brings it to 0.18 m (EKF, not a solver).
  EXPECT_LT(std::abs(r1(0)), 0.4 * std::abs(r0(0)));
  ASSERT_TRUE(ekfUpdate(s, H1, r1, 0.02 * 0.02, true));
  const auto [H2, r2] = plane_range(s);
  EXPECT_LT(std::abs(r2(0)), 0.15 * std::abs(r0(0)));  // measured 0.18 m
  for (int j = 0; j < 3; ++j) EXPECT_NEAR(1.0 / s.features[static_cast<std::size_t>(j)].abr.z(), 10.0, 1.0);
}

// With use_range, a SLAM feature that is not triangulated (hover: no
// parallax) takes its depth prior from the level plane through the beam's hit
// point instead of the fixed prior: seen from 10 m, ground with ±0.5 m relief
// is within 5 % of the plane (plus the filter's pose error), where the fixed
// prior of a 1 m scene (slam_min_depth_m 0.5: ρ0 = 1 1/m) is 90 % off.
TEST(BackendRangeFinder, UntriangulatedFeaturesTakeTheirDepthPriorFromTheRange) {
  const auto traj = test::scenarioTrajectory("hover");
  test::BackendScenario sc = test::hoverScenario(*traj);
  sc.T_B_L = Pose(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()), Vec3::Zero());  // beam along −z of B
  sc.backend.slam_min_depth_m = 0.5;
  sc.backend.slam_triangulated_init = false;
  sc.max_duration_s = 2.0;
  auto run = [&](bool use_range) {
    sc.backend.use_range = use_range;
    return test::runBackendScenario(*traj, sc, 1);
  };
  const test::ScenarioResult with = run(true);
  const test::ScenarioResult without = run(false);
  ASSERT_TRUE(with.status.ok()) << with.status.cause;
  EXPECT_GT(with.stats.slam_initialized_range, 0);
  EXPECT_EQ(with.stats.slam_initialized_prior, 0);  // a reading precedes every initialisation
  EXPECT_EQ(without.stats.slam_initialized_range, 0);
  EXPECT_GT(without.stats.slam_initialized_prior, 0);
  ASSERT_FALSE(with.slam_depth_rel_error.empty());
  ASSERT_FALSE(without.slam_depth_rel_error.empty());
  // The first measurement set with SLAM features: the priors as initialised.
  EXPECT_LT(with.slam_depth_rel_error.front(), 0.08);
  EXPECT_GT(without.slam_depth_rel_error.front(), 0.8);
}

// The information test compares a triangulation with the prior the feature
// would otherwise take: the range finder's priors (σ_ρ = 0.3 ρ, here about
// 0.03 1/m from 10 m) are tighter than the fixed one (σ_ρ0 = 0.5 1/m), so
// with them fewer tracks are triangulated (measured: 4 with the fixed prior,
// none with the range's, over 6 s of the hover's small motion).
TEST(BackendRangeFinder, TriangulationMustBeatTheRangePriorWhereOneIsGiven) {
  const auto traj = test::scenarioTrajectory("hover");
  test::BackendScenario sc = test::hoverScenario(*traj);
  sc.T_B_L = Pose(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal()), Vec3::Zero());  // beam along −z of B
  sc.backend.slam_min_depth_m = 0.5;
  sc.backend.slam_min_parallax_px = 0.0;  // the information test alone
  sc.max_duration_s = 6.0;
  auto run = [&](bool use_range, double relative_sigma) {
    sc.backend.use_range = use_range;
    sc.backend.range_prior_relative_sigma = relative_sigma;
    return test::runBackendScenario(*traj, sc, 1);
  };
  const test::ScenarioResult fixed = run(false, 0.3);
  const test::ScenarioResult range = run(true, 0.3);
  std::printf("triangulated: fixed prior %lld, range prior %lld\n",
              static_cast<long long>(fixed.stats.slam_initialized_triangulated),
              static_cast<long long>(range.stats.slam_initialized_triangulated));
  ASSERT_TRUE(fixed.status.ok()) << fixed.status.cause;
  ASSERT_TRUE(range.status.ok()) << range.status.cause;
  EXPECT_GT(fixed.stats.slam_initialized_triangulated, 0);
  EXPECT_LT(range.stats.slam_initialized_triangulated, fixed.stats.slam_initialized_triangulated);
}

// The prior's geometry, exactly: points on the level plane z = 0.3 seen by a
// camera tilted 35° and rolled, off the origin. Their normalised image
// points give back 1/depth along the camera's z to rounding; rays near or
// above the horizon and depths below the minimum give nothing.
TEST(BackendRangeFinder, LevelPlaneDepthPriorIsExactForPointsOnThePlane) {
  CameraClone c;
  c.p_W_C = Vec3(1.5, -2.0, 7.3);
  c.q_W_C = Quat(Mat3(Vec3(1.0, -1.0, -1.0).asDiagonal())) * so3::expQuat(Vec3(35.0 * M_PI / 180.0, 0.0, 0.0)) *
            so3::expQuat(Vec3(0.0, 0.0, 0.9));  // looking down, tilted 35° about its x, rolled about its axis
  const Mat3 R = c.R_W_C();
  int checked = 0;
  for (const Vec2& xy : {Vec2(0.0, 0.0), Vec2(3.0, 1.0), Vec2(-2.0, 4.0), Vec2(5.0, -3.0)}) {
    const Vec3 p_W(c.p_W_C.x() + xy.x(), c.p_W_C.y() + xy.y(), 0.3);
    const Vec3 p_C = R.transpose() * (p_W - c.p_W_C);
    ASSERT_GT(p_C.z(), 0.0);
    const auto rho = inverseDepthOnLevelPlane(c, Vec2(p_C.x() / p_C.z(), p_C.y() / p_C.z()), 0.3, 0.05);
    ASSERT_TRUE(rho.has_value());
    EXPECT_NEAR(*rho, 1.0 / p_C.z(), 1e-14 / p_C.z());
    ++checked;
  }
  EXPECT_EQ(checked, 4);
  // Rays in the vertical plane of the optical axis (55° below the horizon):
  // 3° below the horizon (sin 0.052 < 0.1) and 10° above it give no prior,
  // 8° below it (sin 0.139) does.
  const Vec3 axis = R.col(2);
  ASSERT_NEAR(std::asin(-axis.z()) * 180.0 / M_PI, 55.0, 1e-9);
  const Vec3 level = Vec3(axis.x(), axis.y(), 0.0).normalized();
  for (const double elevation_deg : {-3.0, 10.0, -8.0}) {
    const double e = elevation_deg * M_PI / 180.0;
    const Vec3 d_C = R.transpose() * (std::cos(e) * level + std::sin(e) * Vec3::UnitZ());
    ASSERT_GT(d_C.z(), 0.0);  // in front of the camera
    const auto rho = inverseDepthOnLevelPlane(c, Vec2(d_C.x() / d_C.z(), d_C.y() / d_C.z()), 0.3, 0.05);
    EXPECT_EQ(rho.has_value(), elevation_deg == -8.0) << elevation_deg;
  }
  // The plane 7 m below, but a minimum depth of 20 m: no prior.
  EXPECT_FALSE(inverseDepthOnLevelPlane(c, Vec2(0.0, 0.0), 0.3, 20.0).has_value());
}

// A range reading waits for max_delay_s of IMU beyond it, so a measurement
// set stamped 20 ms before it that arrives after it is applied in time order
// instead of being dropped as late (max_late_s 5 ms).
TEST(BackendRangeFinder, AReadingDoesNotMakeEarlierMeasurementSetsLate) {
  BackendSensors s{Camera(PinholeCamera(346, 260, Vec4(300, 300, 172.5, 129.5))), Pose(), 9.81, ImuSensor{},
                   std::nullopt, 0};
  s.imu = ImuSensor{0.004316, 0.0004316, 0.0002, 0.00002, 1000};
  s.range_finder = RangeFinderSensor{Pose(), 0.1, 50.0, 0.02};
  BackendOptions o;  // max_delay_s 0.1, max_late_s 0.005
  Backend b(o, s);
  b.initialize(ImuState{});
  const auto imuUntil = [&b](int from_ms, int to_ms) {
    for (int k = from_ms; k <= to_ms; ++k) b.addImu(ImuSample{k * kNsPerMs, Vec3(0, 0, 9.81), Vec3::Zero()});
  };
  imuUntil(1, 450);
  b.addRange(400 * kNsPerMs, 5.0);
  imuUntil(451, 460);
  b.addMeasurementSet(MeasurementSet{380 * kNsPerMs, {}});
  EXPECT_EQ(b.stats().measurements_late_dropped, 0);
  EXPECT_EQ(b.stats().measurement_sets, 1);
  EXPECT_EQ(b.stats().range_updates + b.stats().range_rejected, 0);  // still waiting
  imuUntil(461, 600);
  EXPECT_EQ(b.stats().range_updates + b.stats().range_rejected, 1);  // no SLAM features: rejected
  EXPECT_TRUE(b.status().ok());
}

TEST(BackendZeroVelocity, BoundsVelocityWhenStill) {
  BackendSensors s{Camera(PinholeCamera(346, 260, Vec4(300, 300, 172.5, 129.5))), Pose(), 9.81, ImuSensor{},
                   std::nullopt, 0};
  s.imu = ImuSensor{0.004316, 0.0004316, 0.0002, 0.00002, 1000};
  BackendOptions o;
  o.max_delay_s = 0.0;
  Backend with(o, s), without(o, s);
  ImuState x0;
  x0.v_W = Vec3(0.03, -0.02, 0.01);  // a wrong initial velocity (the truth is 0)
  with.initialize(x0);
  without.initialize(x0);
  for (int k = 1; k <= 2000; ++k) {
    const ImuSample still{k * kNsPerMs, Vec3(0, 0, 9.81), Vec3::Zero()};
    with.addImu(still);
    without.addImu(still);
    if (k % 100 == 0) with.addZeroVelocity(k * kNsPerMs);
  }
  EXPECT_EQ(with.stats().zero_velocity_updates, 20);
  EXPECT_TRUE(with.status().ok());
  const double sv_with = std::sqrt(with.estimate().cov_imu(kIdxV, kIdxV));
  const double sv_without = std::sqrt(without.estimate().cov_imu(kIdxV, kIdxV));
  EXPECT_LT(sv_with, 0.015);  // about the update noise σ 0.01 m/s
  EXPECT_GT(sv_without, 0.04);
  EXPECT_LT(with.estimate().imu.v_W.norm(), 0.01);
  EXPECT_NEAR(without.estimate().imu.v_W.norm(), x0.v_W.norm(), 1e-9);
}

}  // namespace
}  // namespace evio::estimator

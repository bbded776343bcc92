#include "evio/trajectories/bspline_trajectory.h"

#include <gtest/gtest.h>

#include <fstream>

#include "evio/core/io/tum.h"
#include "evio/core/so3.h"
#include "evio/trajectories/trajectory_factory.h"
#include "temp_dir.h"
#include "trajectory_presets.h"

namespace evio {
namespace {

/// Cardinal quintic B-spline on [0, 6) by the truncated-power formula
/// N(x) = 1/5! Σ_{k=0..6} (−1)^k C(6,k) (x − k)₊⁵ — an independent check.
double cardinalQuintic(double x) {
  static constexpr double kBinom[7] = {1, 6, 15, 20, 15, 6, 1};
  double sum = 0.0;
  for (int k = 0; k <= 6; ++k) {
    const double d = x - k;
    if (d > 0.0) sum += ((k % 2) ? -1.0 : 1.0) * kBinom[k] * std::pow(d, 5);
  }
  return sum / 120.0;
}

TEST(QuinticBasis, MatchesTheCardinalSplineAndSumsToOne) {
  for (const double u : {0.0, 0.1, 0.37, 0.5, 0.93, 1.0}) {
    const auto n = quinticBasis(taylor::variable<2>(u));
    double sum = 0, dsum = 0, ddsum = 0;
    for (int r = 0; r <= 5; ++r) {
      // N_r is the basis function of the control point (span − 5 + r): N(u + 5 − r).
      // (the truncated-power sum cancels terms up to 6⁵/120 ≈ 65: ~1e-14 absolute)
      EXPECT_NEAR(n[r].c[0], cardinalQuintic(u + 5 - r), 1e-12) << "u=" << u << " r=" << r;
      EXPECT_NEAR(n[r].c[0], quinticBasis(taylor::variable<2>(1.0 - u))[5 - r].c[0], 1e-15);
      sum += n[r].c[0];
      dsum += n[r].c[1];
      ddsum += n[r].c[2];
    }
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_NEAR(dsum, 0.0, 1e-14);
    EXPECT_NEAR(ddsum, 0.0, 1e-13);
  }
  const auto n0 = quinticBasis(taylor::variable<2>(0.0));
  const double expected[6] = {1, 26, 66, 26, 1, 0};
  for (int r = 0; r <= 5; ++r) EXPECT_NEAR(n0[r].c[0], expected[r] / 120.0, 1e-16);
}

TEST(BSplineTrajectory, ReproducesConstantVelocityAndConstantRateExactly) {
  // Linear position and a constant-rate rotation about a fixed axis lie in
  // the spline's space: away from the clamped ends (3 knots) it reproduces
  // them, and their derivatives, to round-off.
  const Vec3 p0(1, 2, 3), v(0.3, -0.2, 0.1), w(0.2, 0.5, -0.4);
  std::vector<StampedPose> samples;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.1 * i;
    samples.push_back({secondsToNs(t), Pose(so3::expQuat(w * t), p0 + v * t)});
  }
  const BSplineTrajectory spline(samples, 0.1, 0.0, "");
  EXPECT_EQ(spline.controlPoses().size(), 101u);
  for (TimeNs t = secondsToNs(0.35); t <= secondsToNs(9.65); t += 7'300'000) {
    const double ts = nsToSeconds(t);
    const TrajectoryState s = spline.evaluate(t);
    ASSERT_LT((s.T_W_B.translation() - (p0 + v * ts)).norm(), 1e-12) << ts;
    ASSERT_LT(angleBetween(s.T_W_B.quaternion(), so3::expQuat(w * ts)), 1e-12) << ts;
    ASSERT_LT((s.v_W - v).norm(), 1e-12);
    ASSERT_LT(s.a_W.norm(), 1e-10);
    ASSERT_LT((s.omega_B - w).norm(), 1e-12);
    ASSERT_LT(s.alpha_B.norm(), 1e-10);
  }
}

TEST(BSplineTrajectory, SmoothsATumFileOfAnAnalyticMotionToWithinASubmillimetre) {
  // The circle preset sampled at 100 Hz into a TUM file, read back through
  // from_file with 20 ms knots: the spline's bias is ≈ Δ² p''/4 ≈ 0.3 mm
  // (the knot value is (c₋₂ + 26c₋₁ + 66c₀ + 26c₁ + c₂)/120 ≈ c₀ + Δ² c''/4).
  const auto circle = makeTrajectory(test::trajectoryPresetPath("circle.yaml"));
  test::TempDir dir;
  Trajectory poses;
  for (TimeNs t = 0; t <= circle->endTime(); t += 10 * kNsPerMs)
    poses.push_back({t, circle->evaluate(t).T_W_B});
  io::writeTum(dir.file("poses.txt"), poses);
  {
    std::ofstream yaml(dir.file("from_tum.yaml"));
    yaml << "type: from_file\nfile: poses.txt\nknot_interval_s: 0.02\n";
  }
  const auto spline = makeTrajectory(dir.file("from_tum.yaml"));
  EXPECT_EQ(spline->startTime(), 0);
  EXPECT_EQ(spline->endTime(), circle->endTime());
  double max_dp = 0.0, max_dq = 0.0, max_dv = 0.0;
  for (TimeNs t = kNsPerSecond; t <= circle->endTime() - kNsPerSecond; t += 3'700'000) {
    const TrajectoryState a = circle->evaluate(t), b = spline->evaluate(t);
    max_dp = std::max(max_dp, (a.T_W_B.translation() - b.T_W_B.translation()).norm());
    max_dq = std::max(max_dq, angleBetween(a.T_W_B.quaternion(), b.T_W_B.quaternion()));
    max_dv = std::max(max_dv, (a.v_W - b.v_W).norm());
  }
  EXPECT_LT(max_dp, 0.5e-3);
  EXPECT_LT(max_dq * 180.0 / 3.141592653589793, 0.01);
  EXPECT_LT(max_dv, 5e-3);
  std::printf("TUM → spline: max position error %.2e m, attitude %.2e deg, velocity %.2e m/s\n",
              max_dp, max_dq * 180.0 / 3.141592653589793, max_dv);
}

TEST(BSplineTrajectory, RejectsBadSamples) {
  std::vector<StampedPose> one = {{0, Pose()}};
  EXPECT_THROW(BSplineTrajectory(one, 0.1, 0.0, ""), Error);
  std::vector<StampedPose> backwards = {{10, Pose()}, {5, Pose()}};
  EXPECT_THROW(BSplineTrajectory(backwards, 0.1, 0.0, ""), Error);
  std::vector<StampedPose> ok = {{0, Pose()}, {kNsPerSecond, Pose()}};
  EXPECT_THROW(BSplineTrajectory(ok, 0.0, 0.0, ""), Error);
  EXPECT_EQ(BSplineTrajectory(ok, 0.1, 0.5, "").endTime(), kNsPerSecond / 2);
}

}  // namespace
}  // namespace evio

#include "evio/core/pose.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace evio {
namespace {

// Poses T_W_X at 1 s and 3 s: translation (1, 2, 3) m → (3, 2, −1) m,
// rotation identity → 90° about z.
StampedPose at(TimeNs t_ns, double yaw_rad, const Vec3& p_m) {
  return StampedPose{t_ns, Pose(Quat(Eigen::AngleAxisd(yaw_rad, Vec3::UnitZ())), p_m)};
}

const StampedPose kA = at(1'000'000'000, 0.0, Vec3(1, 2, 3));
const StampedPose kB = at(3'000'000'000, std::numbers::pi / 2, Vec3(3, 2, -1));

TEST(PoseInterpolation, Endpoints) {
  const Pose a = interpolatePose(kA, kB, kA.t_ns);
  const Pose b = interpolatePose(kA, kB, kB.t_ns);
  EXPECT_TRUE(a.translation().isApprox(kA.pose.translation(), 1e-15));
  EXPECT_TRUE(b.translation().isApprox(kB.pose.translation(), 1e-15));
  EXPECT_LT(angleBetween(a.quaternion(), kA.pose.quaternion()), 1e-12);
  EXPECT_LT(angleBetween(b.quaternion(), kB.pose.quaternion()), 1e-12);
}

TEST(PoseInterpolation, MidpointAboutOneAxis) {
  const Pose m = interpolatePose(kA, kB, 2'000'000'000);
  EXPECT_TRUE(m.translation().isApprox(Vec3(2, 2, 1), 1e-15));
  const Quat expected(Eigen::AngleAxisd(std::numbers::pi / 4, Vec3::UnitZ()));
  EXPECT_LT(angleBetween(m.quaternion(), expected), 1e-12);
  EXPECT_NEAR(m.quaternion().norm(), 1.0, 1e-15);
}

TEST(PoseInterpolation, QuarterAngleGrowsLinearly) {
  // At s = 1/4: position (1.5, 2, 2) m, rotation 22.5° about z.
  const Pose q = interpolatePose(kA, kB, 1'500'000'000);
  EXPECT_TRUE(q.translation().isApprox(Vec3(1.5, 2, 2), 1e-15));
  const Vec3 x_W = q * Vec3::UnitX() - q.translation();
  EXPECT_NEAR(std::atan2(x_W.y(), x_W.x()), std::numbers::pi / 8, 1e-12);
  EXPECT_NEAR(x_W.z(), 0.0, 1e-15);
}

TEST(PoseInterpolation, FirstPoseAtOrAfter) {
  const Trajectory trajectory = {kA, kB};
  EXPECT_EQ(firstPoseAtOrAfter(trajectory, 0), trajectory.begin());
  EXPECT_EQ(firstPoseAtOrAfter(trajectory, kA.t_ns), trajectory.begin());
  EXPECT_EQ(firstPoseAtOrAfter(trajectory, kA.t_ns + 1), trajectory.begin() + 1);
  EXPECT_EQ(firstPoseAtOrAfter(trajectory, kB.t_ns), trajectory.begin() + 1);
  EXPECT_EQ(firstPoseAtOrAfter(trajectory, kB.t_ns + 1), trajectory.end());
  EXPECT_EQ(firstPoseAtOrAfter(Trajectory{}, 0), Trajectory{}.end());
}

}  // namespace
}  // namespace evio

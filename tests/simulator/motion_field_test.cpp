#include "evio/simulator/motion_field.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>

#include "numeric_jacobian.h"

namespace evio::simulator {
namespace {

std::vector<Camera> cameras() {
  RadTanCamera::Params r;
  r << 320, 310, 160, 120, -0.2, 0.05, 0.001, -0.002, 0.0;
  EquidistantCamera::Params e;
  e << 200, 200, 160, 120, 0.1, -0.02, 0.003, -0.001;
  return {PinholeCamera(320, 240, Vec4(300, 300, 160, 120)), RadTanCamera(320, 240, r),
          EquidistantCamera(320, 240, e)};
}

TEST(MotionField, PointFlowIsTheDerivativeOfTheProjection) {
  const CameraVelocity vel{Vec3(0.5, -0.2, 0.8), Vec3(-0.3, 0.4, 0.1)};
  const Vec3 p0(0.4, -0.3, 3.0);
  for (const Camera& cam : cameras()) {
    SCOPED_TRACE(std::string(cam.model()));
    // p_C(t) solves ṗ = −v − ω × p; take the derivative at t = 0 numerically.
    const Vec3 p_dot = -vel.v_C - vel.omega_C.cross(p0);
    const auto uv_of_t = [&](const Eigen::Matrix<double, 1, 1>& t) {
      Vec2 uv;
      EXPECT_TRUE(cam.project(p0 + t(0) * p_dot, &uv));
      return uv;
    };
    const Vec2 expected = test::numericJacobian<2, 1>(uv_of_t, Eigen::Matrix<double, 1, 1>::Zero(), 1e-6);
    Vec2 f;
    ASSERT_TRUE(pointFlow(cam, p0, vel, &f));
    EXPECT_NEAR((f - expected).norm(), 0.0, 1e-5 * (1.0 + expected.norm()));
  }
}

TEST(MotionField, PointsAtInfinityMoveWithTheRotationOnly) {
  const CameraVelocity vel{Vec3(5.0, 1.0, -2.0), Vec3(0.1, -0.2, 0.3)};
  const Vec3 b = Vec3(0.1, 0.05, 1.0).normalized();
  for (const Camera& cam : cameras()) {
    Vec2 at_inf, far;
    ASSERT_TRUE(directionFlow(cam, b, vel, &at_inf));
    ASSERT_TRUE(pointFlow(cam, b * 1e12, vel, &far));
    EXPECT_NEAR((at_inf - far).norm(), 0.0, 1e-6);
    ASSERT_TRUE(directionFlow(cam, 3.0 * b, vel, &far));  // any point on the ray
    EXPECT_NEAR((at_inf - far).norm(), 0.0, 1e-9);
  }
}

TEST(MotionField, FromDepthHandlesInfinityAndMissingPixels) {
  const Camera cam = cameras()[1];
  cv::Mat depth(cam.height(), cam.width(), CV_32FC1, cv::Scalar(2.0f));
  depth.at<float>(10, 20) = std::numeric_limits<float>::infinity();
  depth.at<float>(11, 20) = std::numeric_limits<float>::quiet_NaN();
  const CameraVelocity vel{Vec3(0.2, 0.0, 0.0), Vec3(0.0, 0.1, 0.0)};
  const cv::Mat f = motionFieldFromDepth(cam, depth, vel);
  Vec3 b;
  ASSERT_TRUE(cam.unproject(Vec2(20, 10), &b));
  Vec2 expected;
  ASSERT_TRUE(directionFlow(cam, b, vel, &expected));
  EXPECT_NEAR(f.at<cv::Vec2f>(10, 20)[0], expected.x(), 1e-4);
  EXPECT_TRUE(std::isnan(f.at<cv::Vec2f>(11, 20)[0]));
  ASSERT_TRUE(cam.unproject(Vec2(5, 7), &b));
  ASSERT_TRUE(pointFlow(cam, b * (2.0 / b.z()), vel, &expected));
  EXPECT_NEAR(f.at<cv::Vec2f>(7, 5)[1], expected.y(), 1e-4);
}

/// The bits of a flow vector, signs of zero included.
std::array<std::uint64_t, 2> bitsOf(const Vec2& f) {
  std::array<std::uint64_t, 2> b{};
  std::memcpy(b.data(), f.data(), sizeof(b));
  return b;
}

TEST(MotionField, PinholeFlowGivesTheBitsOfTheGeneralFunctions) {
  const PinholeCamera pinhole(346, 260, Vec4(259.4, 260.1, 172.3, 128.9));
  const Camera cam = pinhole;
  const PinholeFlow fast(pinhole);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::uniform_real_distribution<float> range(0.01f, 30.0f);
  int compared = 0, rejected = 0;
  for (int i = 0; i < 200000; ++i) {
    // Velocities with zero components too (exact zeros in the sums).
    CameraVelocity vel{Vec3(u(rng), u(rng), u(rng)), Vec3(u(rng), u(rng), u(rng))};
    if (i % 7 == 0) vel.v_C.x() = 0.0;
    if (i % 11 == 0) vel.omega_C = Vec3::Zero();
    if (i % 13 == 0) vel.v_C = Vec3::Zero();
    // A pixel's bearing (float, as the renderer's) at a float range; some behind the camera.
    const Eigen::Vector3f b = Vec3(u(rng), u(rng), i % 97 == 0 ? -0.5 : 1.0).normalized().cast<float>();
    const Vec3 bd = b.cast<double>();
    const Vec3 p = bd * static_cast<double>(range(rng));
    Vec2 expected, got;
    const bool ok_point = pointFlow(cam, p, vel, &expected);
    ASSERT_EQ(fast.point(p, vel, &got), ok_point) << i;
    if (ok_point) {
      ASSERT_EQ(bitsOf(got), bitsOf(expected)) << i;
      ++compared;
    } else {
      ++rejected;
    }
    const bool ok_direction = directionFlow(cam, bd, vel, &expected);
    ASSERT_EQ(fast.direction(bd, vel, &got), ok_direction) << i;
    if (ok_direction) {
      ASSERT_EQ(bitsOf(got), bitsOf(expected)) << i;
    }
  }
  EXPECT_GT(compared, 190000);
  EXPECT_GT(rejected, 1000);
  Vec2 f;
  EXPECT_FALSE(fast.point(Vec3(0.0, 0.0, std::numeric_limits<double>::infinity()), CameraVelocity{}, &f));
}

}  // namespace
}  // namespace evio::simulator

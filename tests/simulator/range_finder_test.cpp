// The range finder against analytic ranges to a plane: ρ = (d − n·o)/(n·u)
// for the beam o + ρ u, through the rig's T_B_L; no return outside
// [min, max] or without a surface; noise with the stated σ.
#include "evio/simulator/range_finder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <sstream>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/scenes/scene_description.h"

namespace evio::simulator {
namespace {

/// A 400 m square horizontal plane at height z0 (normal +z).
std::string groundScene(double z0) {
  std::ostringstream s;
  s << "materials:\n  - {name: m, albedo: {type: constant, value: 0.3}}\n"
    << "lights:\n  - {type: sky, radiance_w_m2_sr: 1}\n"
    << "sources:\n  - {type: plane, material: m, size_m: [400, 400], position_m: [0, 0, " << z0 << "]}\n";
  return s.str();
}

RangeFinderSensor downLooking(double sigma) {
  RangeFinderSensor s;
  // L's +z (the beam) along −z of B, offset 0.1 m along x of B.
  s.T_B_L = Pose(so3::expQuat(Vec3(std::numbers::pi, 0.0, 0.0)), Vec3(0.1, 0.0, 0.0));
  s.min_range_m = 0.3;
  s.max_range_m = 40.0;
  s.noise_sigma_m = sigma;
  return s;
}

TEST(RangeFinder, MatchesAnalyticRangesToAPlane) {
  const double z0 = -0.5;
  const scenes::Scene scene(scenes::loadSceneString(groundScene(z0), "ground.yaml"));
  RangeFinder rf(downLooking(0.0), RangeFinder::sceneRayCast(scene), 1);
  int valid = 0;
  for (int k = 0; k < 200; ++k) {
    // Heights 0.5 .. 60 m, tilts up to ±60°.
    const double height = 0.5 + 0.3 * k;
    const Vec3 tilt(0.9 * std::sin(0.37 * k), 0.9 * std::cos(0.23 * k), 0.5 * k);
    const Pose T_W_B(so3::expQuat(tilt), Vec3(1.0 + 0.1 * k, -2.0, z0 + height));
    const Pose T_W_L = T_W_B * rf.sensor().T_B_L;
    const Vec3 o = T_W_L.translation(), u = T_W_L.rotation().col(2);
    const double rho = u.z() < 0.0 ? (z0 - o.z()) / u.z() : std::numeric_limits<double>::infinity();
    const RangeMeasurement m = rf.measure(k * 10 * kNsPerMs, T_W_B);
    EXPECT_EQ(m.reading.t_ns, k * 10 * kNsPerMs);
    if (std::isfinite(rho) && rho < 150.0) {  // the plane ends 200 m out
      EXPECT_NEAR(m.true_range_m, rho, 1e-5 * std::max(1.0, rho)) << k;  // float rays
    } else if (!std::isfinite(rho)) {
      EXPECT_FALSE(std::isfinite(m.true_range_m));
    }
    const bool in_range = std::isfinite(rho) && rho >= 0.3 + 1e-4 && rho <= 40.0 - 1e-4;
    const bool out_range = !std::isfinite(rho) || rho < 0.3 - 1e-4 || rho > 40.0 + 1e-4;
    if (in_range) {
      EXPECT_TRUE(m.reading.valid) << k;
      EXPECT_NEAR(m.reading.range_m, rho, 1e-5 * std::max(1.0, rho)) << k;
      ++valid;
    }
    if (out_range) {
      EXPECT_FALSE(m.reading.valid) << k;
      EXPECT_EQ(m.reading.range_m, 0.0);
    }
  }
  EXPECT_GT(valid, 50);
}

TEST(RangeFinder, NoiseHasTheStatedSigma) {
  // Analytic ray cast (a plane at distance 10 m along the beam) to isolate the noise.
  const RangeFinder::RayCast wall = [](const Vec3&, const Vec3&) { return 10.0; };
  RangeFinder rf(downLooking(0.02), wall, 7);
  double sum = 0.0, sum2 = 0.0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    const RangeMeasurement m = rf.measure(k, Pose());
    ASSERT_TRUE(m.reading.valid);
    sum += m.reading.range_m - 10.0;
    sum2 += (m.reading.range_m - 10.0) * (m.reading.range_m - 10.0);
  }
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 4.0 * 0.02 / std::sqrt(n));
  EXPECT_NEAR(sd, 0.02, 0.10 * 0.02);
}

TEST(RangeFinder, RejectsAnInvalidSensor) {
  RangeFinderSensor s = downLooking(0.0);
  s.max_range_m = 0.1;  // below min_range_m
  const RangeFinder::RayCast wall = [](const Vec3&, const Vec3&) { return 1.0; };
  EXPECT_THROW(RangeFinder(s, wall, 1), Error);
  EXPECT_THROW(RangeFinder(downLooking(0.0), RangeFinder::RayCast{}, 1), Error);
}

}  // namespace
}  // namespace evio::simulator

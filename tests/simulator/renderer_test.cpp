// The renderer against exact ground truth: depth of planes, Lambertian
// radiance under the sun, shadow = ambient only, rays = unprojection
// (distortion included), motion field = finite differences of projections,
// and bit-identical output for any thread count.
#include "evio/simulator/renderer.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstring>
#include <numbers>
#include <tuple>

#include "evio/core/cpu_features.h"
#include "evio/core/error.h"
#include "evio/scenes/scene_description.h"

namespace evio::simulator {
namespace {

using scenes::Scene;
using scenes::loadSceneString;

Camera pinhole(int w = 64, int h = 48) { return PinholeCamera(w, h, Vec4(50.0, 52.0, 31.7, 23.2)); }
Camera radtan(int w = 64, int h = 48) {
  RadTanCamera::Params p;
  p << 50.0, 52.0, 31.7, 23.2, -0.25, 0.08, 0.002, -0.001, 0.01;
  return RadTanCamera(w, h, p);
}
Camera equidistant(int w = 64, int h = 48) {
  EquidistantCamera::Params p;
  p << 40.0, 40.0, 31.5, 23.5, 0.05, -0.01, 0.002, -0.0005;
  return EquidistantCamera(w, h, p);
}

RendererOptions threads(int n) {
  RendererOptions o;
  o.threads = n;
  o.tile_px = 8;
  return o;
}

bool bitEqual(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() &&
         std::memcmp(a.data, b.data, a.total() * a.elemSize()) == 0;
}

/// A plane with unit normal n at signed distance d from the origin
/// (n·x = d), as a scene: a 200 m square plane with that orientation.
std::string planeScene(const Vec3& n, double d, double albedo, const std::string& lights) {
  // rotation taking +z to n: pitch then yaw.
  const double pitch = std::acos(std::clamp(n.z(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  const double yaw = std::atan2(n.y(), n.x()) * 180.0 / std::numbers::pi;
  const Vec3 c = d * n;
  std::ostringstream s;
  s.precision(17);
  s << "materials:\n  - {name: m, albedo: {type: constant, value: " << albedo << "}}\n"
    << "lights:\n" << lights << "sources:\n"
    << "  - {type: plane, material: m, size_m: [200, 200], position_m: [" << c.x() << ", " << c.y() << ", "
    << c.z() << "], rotation_deg: [0, " << pitch << ", " << yaw << "]}\n";
  return s.str();
}

TEST(Renderer, DepthOfATiltedPlaneIsExact) {
  const Vec3 n = Vec3(0.3, -0.4, 1.0).normalized();  // plane below the camera, tilted
  const double d = -2.5;                              // n·x = d: 2.5 m from the origin
  const Scene scene(loadSceneString(planeScene(n, d, 0.5, "  - {type: sky, radiance_w_m2_sr: 1}\n"), "s.yaml"));
  // Camera at the origin looking down the plane's normal, turned 25° away.
  const Mat3 R = scenes::lookAtRotation(Vec3::Zero(), -n + Vec3(0.2, 0.3, 0.0), Vec3::UnitX());
  for (const Camera& cam : {pinhole(), radtan(), equidistant()}) {
    SCOPED_TRACE(std::string(cam.model()));
    const Renderer renderer(scene, cam, threads(2));
    const RenderOutput out = renderer.render(Pose(R, Vec3::Zero()));
    int hits = 0;
    for (int y = 0; y < cam.height(); ++y)
      for (int x = 0; x < cam.width(); ++x) {
        Vec3 b;
        ASSERT_TRUE(cam.unproject(Vec2(x, y), &b));
        const double nb = n.dot(R * b);
        if (!(d / nb > 0.0)) continue;
        // Ray t·R·b (b unit) meets n·x = d at t = d / (n·R b); depth = z_C = t · b_z.
        const double z_expected = d / nb * b.z();
        EXPECT_NEAR(out.depth.at<float>(y, x), z_expected, 2e-6 * z_expected + 1e-6) << x << "," << y;
        const cv::Vec3f nn = out.normal.at<cv::Vec3f>(y, x);
        EXPECT_NEAR(nn[0], n.x(), 1e-6);
        EXPECT_NEAR(nn[2], n.z(), 1e-6);
        ++hits;
      }
    EXPECT_GT(hits, cam.width() * cam.height() / 2);
  }
}

TEST(Renderer, LambertianPlaneUnderTheSunHasRadianceRhoECosOverPi) {
  const double rho = 0.3, e = 590.0, az = 40.0, el = 35.0;
  const Vec3 n = Vec3(0.1, 0.2, 1.0).normalized();
  const std::string sun = "  - {type: sun, azimuth_deg: 40, elevation_deg: 35, irradiance_w_m2: 590}\n";
  const Scene scene(loadSceneString(planeScene(n, -3.0, rho, sun), "s.yaml"));
  const Vec3 s = scenes::sunDirection(az, el);
  const double expected = rho * e * n.dot(s) / std::numbers::pi;
  const Renderer renderer(scene, radtan(), threads(2));
  const Mat3 R = scenes::lookAtRotation(Vec3::Zero(), -n + Vec3(0.3, 0.1, 0.0), Vec3::UnitX());
  const RenderOutput out = renderer.render(Pose(R, Vec3::Zero()));
  int hits = 0;
  for (int y = 0; y < out.radiance.rows; ++y)
    for (int x = 0; x < out.radiance.cols; ++x) {
      if (!std::isfinite(out.depth.at<float>(y, x))) continue;
      EXPECT_NEAR(out.radiance.at<float>(y, x), expected, 2e-6 * expected);
      ++hits;
    }
  EXPECT_GT(hits, 1000);
}

TEST(Renderer, PointInShadowReceivesOnlyAmbientLight) {
  // Ground z = 0, a 2 m wall (x ∈ [-0.2, 0.2]) and the sun low in the east:
  // the ground west of the wall, out to 2 / tan(el), is in shadow.
  const double rho = 0.25, l_sky = 4.0, el = 30.0;
  const std::string yaml =
      "materials:\n  - {name: m, albedo: {type: constant, value: 0.25}}\n"
      "lights:\n  - {type: sun, azimuth_deg: 90, elevation_deg: 30, irradiance_w_m2: 590}\n"
      "  - {type: sky, radiance_w_m2_sr: 4}\n"
      "sources:\n  - {type: plane, material: m, size_m: [60, 60]}\n"
      "  - {type: box, material: m, position_m: [0, 0, 1], size_m: [0.4, 40, 2]}\n";
  const Scene scene(loadSceneString(yaml, "s.yaml"));
  const double shadow_end = -0.2 - 2.0 / std::tan(el * std::numbers::pi / 180.0);
  const Camera cam = pinhole(80, 60);
  const Renderer renderer(scene, cam, threads(2));
  const Vec3 c(-2.0, -4.0, 3.0);
  const Mat3 R = scenes::lookAtRotation(c, Vec3(-2.0, 1.0, 0.0), Vec3::UnitZ());
  const RenderOutput out = renderer.render(Pose(R, c));
  const double ambient = rho * l_sky;  // ρ/π · π L (1 + n_z)/2 with n_z = 1
  const double sunlit = ambient + rho * 590.0 * std::sin(el * std::numbers::pi / 180.0) / std::numbers::pi;
  int in_shadow = 0, in_sun = 0;
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const float z = out.depth.at<float>(y, x);
      if (!std::isfinite(z) || out.normal.at<cv::Vec3f>(y, x)[2] < 0.999f) continue;  // ground only
      Vec3 b;
      cam.unproject(Vec2(x, y), &b);
      const Vec3 p = c + R * (b * (static_cast<double>(z) / b.z()));
      if (std::abs(p.z()) > 1e-4) continue;  // the wall's top
      const float l = out.radiance.at<float>(y, x);
      if (p.x() > shadow_end + 0.05 && p.x() < -0.25 && std::abs(p.y()) < 19.0) {
        EXPECT_NEAR(l, ambient, 1e-5 * ambient) << p.transpose();
        ++in_shadow;
      } else if (p.x() < shadow_end - 0.05) {
        EXPECT_NEAR(l, sunlit, 1e-5 * sunlit) << p.transpose();
        ++in_sun;
      }
    }
  EXPECT_GT(in_shadow, 200);
  EXPECT_GT(in_sun, 200);
}

TEST(Renderer, ShadowWithIndirectLightReceivesBounceLight) {
  // As above with the irradiance cache and no sky. A plane cannot see
  // itself, so the shadowed ground sees only the wall's shadowed face, which
  // is lit by the sunlit ground: with one bounce the ground stays black, the
  // second bounce lights it.
  const std::string yaml =
      "indirect: {bounces: 2, directions: 64}\n"
      "materials:\n  - {name: m, albedo: {type: constant, value: 0.25}}\n"
      "lights:\n  - {type: sun, azimuth_deg: 90, elevation_deg: 30, irradiance_w_m2: 590}\n"
      "sources:\n  - {type: plane, material: m, size_m: [30, 30], cell_m: 0.5}\n"
      "  - {type: box, material: m, position_m: [0, 0, 1], size_m: [0.4, 20, 2], cell_m: 0.5}\n";
  const Scene scene(loadSceneString(yaml, "s.yaml"));
  const Renderer renderer(scene, pinhole(), threads(2));
  const Vec3 c(-1.5, -3.0, 2.0);
  const RenderOutput out = renderer.render(Pose(scenes::lookAtRotation(c, Vec3(-1.5, 1.0, 0.0), Vec3::UnitZ()), c));
  // Pixels on the shadowed ground (x ∈ [-3.2, -0.3]) are lit by bounce only: 0 < L.
  const Camera cam = pinhole();
  int checked = 0;
  for (int y = 0; y < cam.height(); ++y)
    for (int x = 0; x < cam.width(); ++x) {
      const float z = out.depth.at<float>(y, x);
      if (!std::isfinite(z)) continue;
      Vec3 b;
      cam.unproject(Vec2(x, y), &b);
      const Vec3 p = c + scenes::lookAtRotation(c, Vec3(-1.5, 1.0, 0.0), Vec3::UnitZ()) * (b * (static_cast<double>(z) / b.z()));
      if (std::abs(p.z()) > 1e-4 || p.x() < -3.0 || p.x() > -0.4 || std::abs(p.y()) > 9.0) continue;
      const float l = out.radiance.at<float>(y, x);
      EXPECT_GT(l, 0.0f);
      EXPECT_LT(l, 0.25f * 590.0f * 0.5f / std::numbers::pi_v<float>);  // below the direct sunlit value
      ++checked;
    }
  EXPECT_GT(checked, 100);
}

TEST(Renderer, RaysAreTheCameraUnprojectionIncludingDistortion) {
  // A fronto-parallel plane at z = 4: the hit of pixel (x, y) projects back
  // onto (x, y), and the renderer's ray is the model's unprojection.
  const Scene scene(loadSceneString(planeScene(Vec3(0, 0, -1), -4.0, 0.5, "  - {type: sky, radiance_w_m2_sr: 1}\n"),
                                    "s.yaml"));
  for (const Camera& cam : {pinhole(), radtan(), equidistant()}) {
    SCOPED_TRACE(std::string(cam.model()));
    const Renderer renderer(scene, cam, threads(1));
    const RenderOutput out = renderer.render(Pose::identity());  // C = W, looking along +z
    for (int y = 0; y < cam.height(); y += 3)
      for (int x = 0; x < cam.width(); x += 3) {
        Vec3 b;
        ASSERT_TRUE(cam.unproject(Vec2(x, y), &b));
        const Eigen::Vector3f rb = renderer.bearing(x, y);
        EXPECT_NEAR((rb.cast<double>() - b).norm(), 0.0, 2e-7);  // float bearings
        const double z = out.depth.at<float>(y, x);
        EXPECT_NEAR(z, 4.0, 1e-5);
        Vec2 uv;
        ASSERT_TRUE(cam.project(b * (z / b.z()), &uv));
        EXPECT_NEAR(uv.x(), x, 1e-4);
        EXPECT_NEAR(uv.y(), y, 1e-4);
      }
  }
}

TEST(Renderer, MotionFieldAgreesWithFiniteDifferencesOfProjections) {
  const std::string sky = "  - {type: sky, radiance_w_m2_sr: 1}\n";
  const Scene scene(loadSceneString(planeScene(Vec3(0.2, 0.1, 1.0).normalized(), -3.0, 0.5, sky), "s.yaml"));
  const CameraVelocity vel{Vec3(0.7, -0.3, 0.4), Vec3(0.2, -0.5, 0.3)};
  const Vec3 p0(0.2, -0.1, 0.3);
  const Mat3 R0 = scenes::lookAtRotation(p0, Vec3(0.5, 0.8, -3.0), Vec3::UnitX());
  const Pose T0(R0, p0);
  // Any pose curve through T0 with ṗ = R0 v and Ṙ = R0 [ω]× at t = 0 has the
  // same first derivative of the projections; take (R0 Exp(ω t), p0 + R0 v t).
  const auto poseAt = [&](double t) {
    return Pose(Mat3(R0 * Eigen::AngleAxisd(vel.omega_C.norm() * t, vel.omega_C.normalized()).toRotationMatrix()),
                Vec3(p0 + R0 * vel.v_C * t));
  };
  for (const Camera& cam : {pinhole(), radtan(), equidistant()}) {
    SCOPED_TRACE(std::string(cam.model()));
    const Renderer renderer(scene, cam, threads(2));
    const RenderOutput out = renderer.render(T0, &vel);
    int checked = 0;
    for (int y = 2; y < cam.height(); y += 5)
      for (int x = 2; x < cam.width(); x += 5) {
        const float z = out.depth.at<float>(y, x);
        if (!std::isfinite(z)) continue;
        Vec3 b;
        cam.unproject(Vec2(x, y), &b);
        const Vec3 p_W = T0 * (b * (static_cast<double>(z) / b.z()));
        const double dt = 1e-4;
        Vec2 up, um;
        ASSERT_TRUE(cam.project(poseAt(dt).inverse() * p_W, &up));
        ASSERT_TRUE(cam.project(poseAt(-dt).inverse() * p_W, &um));
        const Vec2 fd = (up - um) / (2 * dt);
        const cv::Vec2f f = out.flow.at<cv::Vec2f>(y, x);
        // Central differences are exact to O(dt²); the depth is float.
        EXPECT_NEAR(f[0], fd.x(), 1e-3 * (1.0 + fd.norm())) << x << "," << y;
        EXPECT_NEAR(f[1], fd.y(), 1e-3 * (1.0 + fd.norm())) << x << "," << y;
        ++checked;
      }
    EXPECT_GT(checked, 50);
    // The same field from the depth image alone.
    const cv::Mat from_depth = motionFieldFromDepth(cam, out.depth, vel);
    for (int y = 0; y < cam.height(); ++y)
      for (int x = 0; x < cam.width(); ++x) {
        const cv::Vec2f a = out.flow.at<cv::Vec2f>(y, x), b = from_depth.at<cv::Vec2f>(y, x);
        EXPECT_NEAR(a[0], b[0], 1e-3 * (1.0 + std::abs(static_cast<double>(a[0]))));
        EXPECT_NEAR(a[1], b[1], 1e-3 * (1.0 + std::abs(static_cast<double>(a[1]))));
      }
  }
}

TEST(Renderer, OutputIsBitIdenticalForAnyThreadCount) {
  const char* yaml =
      "seed: 4\n"
      "materials:\n"
      "  - {name: ground, model: oren_nayar, roughness_deg: 25, albedo: {type: noise}}\n"
      "  - {name: rock, albedo: {type: collage, region_m: [3, 3], count: 30}}\n"
      "lights:\n  - {type: sun, azimuth_deg: 120, elevation_deg: 25, irradiance_w_m2: 590}\n"
      "  - {type: sky, radiance_w_m2_sr: 6}\n"
      "  - {type: point, position_m: [1, -1, 2], intensity_w_sr: 20}\n"
      "sources:\n"
      "  - {type: terrain, name: t, material: ground, size_m: [12, 12], cell_m: 0.2, crater_count: 4,\n"
      "     crater_radius_m: [0.3, 1.5]}\n"
      "  - {type: rocks, material: rock, ground: t, region_size_m: [8, 8], count: 25}\n";
  const Scene a(loadSceneString(yaml, "s.yaml"));
  const Scene b(loadSceneString(yaml, "s.yaml"));  // built a second time
  const Camera cam = radtan(120, 90);
  const Vec3 c(0, -5, 3);
  const Pose T(scenes::lookAtRotation(c, Vec3(0, 0, 0), Vec3::UnitZ()), c);
  const CameraVelocity vel{Vec3(0.3, 0, 0.1), Vec3(0, 0.2, 0)};
  RendererOptions super = threads(1);
  super.supersampling = 2;
  const RenderOutput r1 = Renderer(a, cam, threads(1)).render(T, &vel);
  const RenderOutput r2 = Renderer(a, cam, threads(2)).render(T, &vel);
  const RenderOutput r3 = Renderer(b, cam, threads(2)).render(T, &vel);
  for (const RenderOutput* r : {&r2, &r3}) {
    EXPECT_TRUE(bitEqual(r1.radiance, r->radiance));
    EXPECT_TRUE(bitEqual(r1.depth, r->depth));
    EXPECT_TRUE(bitEqual(r1.normal, r->normal));
    EXPECT_TRUE(bitEqual(r1.flow, r->flow));
  }
  RendererOptions super2 = super;
  super2.threads = 2;
  EXPECT_TRUE(bitEqual(Renderer(a, cam, super).render(T).radiance, Renderer(a, cam, super2).render(T).radiance));
  double sum = 0.0;
  for (int y = 0; y < r1.radiance.rows; ++y)
    for (int x = 0; x < r1.radiance.cols; ++x) sum += static_cast<double>(r1.radiance.at<float>(y, x));
  EXPECT_GT(sum, 0.0);
}

/// Every texture kind, every light kind, both reflectance models and the
/// indirect-light cache in one small scene.
const char* const kEveryShadingFeature =
    "seed: 3\n"
    "indirect: {bounces: 1, directions: 16}\n"
    "materials:\n"
    "  - {name: ground, model: oren_nayar, roughness_deg: 25, albedo: {type: noise, octaves: 7}}\n"
    "  - {name: poster, albedo: {type: collage, region_m: [2, 1.5], count: 40}}\n"
    "  - {name: paper, albedo: {type: shapes, region_m: [1.5, 1], count: 9}}\n"
    "  - {name: board, albedo: {type: checker, value: 0.8, value_b: 0.1, square_m: 0.1}}\n"
    "  - {name: grey, albedo: {type: constant, value: 0.4}}\n"
    "lights:\n"
    "  - {type: sun, azimuth_deg: 120, elevation_deg: 25, irradiance_w_m2: 590}\n"
    "  - {type: sky, radiance_w_m2_sr: 6}\n"
    "  - {type: point, position_m: [1, -1, 2], intensity_w_sr: 20}\n"
    "  - {type: spot, position_m: [-1, -2, 3], target_m: [0, 0, 0.5], intensity_w_sr: 80,\n"
    "     inner_angle_deg: 15, outer_angle_deg: 30}\n"
    "sources:\n"
    "  - {type: terrain, name: t, material: ground, size_m: [12, 12], cell_m: 0.25, crater_count: 3,\n"
    "     crater_radius_m: [0.3, 1.5]}\n"
    "  - {type: plane, material: poster, position_m: [-1.2, 1, 1], rotation_deg: [90, 0, 0], size_m: [2, 1.5]}\n"
    "  - {type: plane, material: paper, position_m: [1.2, 1, 1], rotation_deg: [90, 0, 10], size_m: [1.5, 1]}\n"
    "  - {type: box, material: board, position_m: [0.2, -0.5, 0.4], size_m: [0.5, 0.5, 0.5], rotation_deg: [0, 0, 30]}\n"
    "  - {type: box, material: grey, position_m: [-0.6, -0.8, 0.3], size_m: [0.3, 0.4, 0.6]}\n";

TEST(Renderer, Avx2PathRendersTheSameBitsAsTheBaselinePath) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "this CPU has no AVX2: only the baseline path runs";
  const Scene scene(loadSceneString(kEveryShadingFeature, "s.yaml"));
  const CameraVelocity vel{Vec3(0.3, 0, 0.1), Vec3(0, 0.2, 0.05)};
  // Near and far views (footprints below and above one texel: every mip
  // level), with distortion, at two supersampling settings.
  const Vec3 views[][2] = {{Vec3(0, -4, 2.5), Vec3(0, 0.5, 0.5)},
                           {Vec3(-1.0, -0.2, 1.1), Vec3(-1.2, 1, 1)},
                           {Vec3(0.5, -0.8, 1.0), Vec3(1.2, 1, 0.9)},
                           {Vec3(0, -6, 5), Vec3(0, 0, 0)}};
  // Tiles of 8 px (whole groups of eight rays) and of 6 and 13 px on odd
  // image sizes (groups that straddle tile rows, padded last groups, rows
  // whose length is not a multiple of eight, unaligned output rows).
  for (const auto& [n, tile] : {std::pair{1, 8}, std::pair{2, 8}, std::pair{1, 6}, std::pair{1, 13}}) {
    RendererOptions base = threads(2);
    base.supersampling = n;
    base.tile_px = tile;
    base.avx2 = false;
    RendererOptions avx = base;
    avx.avx2 = true;
    // A pinhole camera (the 4-pixel flow path), a distorted camera, and a
    // fisheye whose corners have no ray (NaN bearings).
    EquidistantCamera::Params fisheye;
    fisheye << 18.0, 18.0, 47.5, 35.5, -0.05, 0.0, 0.0, 0.0;
    const int w = tile == 8 ? 96 : 97, h = tile == 8 ? 72 : 71;
    const Camera pinhole = PinholeCamera(w, h, Vec4(60.0, 61.0, 0.5 * (w - 1), 0.5 * (h - 1)));
    for (const Camera& cam : {pinhole, radtan(w, h), Camera(EquidistantCamera(w, h, fisheye))}) {
    const Renderer r_base(scene, cam, base), r_avx(scene, cam, avx);
    int no_ray = 0;
    for (int y = 0; y < cam.height(); ++y)
      for (int x = 0; x < cam.width(); ++x) no_ray += std::isnan(r_base.bearing(x, y).x()) ? 1 : 0;
    if (cam.model() == std::string("equidistant")) {
      EXPECT_GT(no_ray, 0);  // the case is covered
    }
    for (const auto& v : views) {
      SCOPED_TRACE(::testing::Message() << cam.model() << ", supersampling " << n << ", tiles of " << tile
                                        << " px, camera at " << v[0].transpose());
      const Pose T(scenes::lookAtRotation(v[0], v[1], Vec3::UnitZ()), v[0]);
      const RenderOutput a = r_base.render(T, &vel);
      const RenderOutput b = r_avx.render(T, &vel);
      EXPECT_TRUE(bitEqual(a.radiance, b.radiance));
      EXPECT_TRUE(bitEqual(a.depth, b.depth));
      EXPECT_TRUE(bitEqual(a.normal, b.normal));
      EXPECT_TRUE(bitEqual(a.flow, b.flow));
      EXPECT_GT(cv::countNonZero(a.radiance > 0.0f), a.radiance.total() / 8);  // the views see the scene
    }
    }
  }
}

/// Whether the pixels of `rect` in a and b have the same bits.
bool rectBitEqual(const cv::Mat& a, const cv::Mat& b, const cv::Rect& rect) {
  for (int y = rect.y; y < rect.y + rect.height; ++y)
    if (std::memcmp(a.ptr(y, rect.x), b.ptr(y, rect.x), static_cast<std::size_t>(rect.width) * a.elemSize()) != 0)
      return false;
  return true;
}

TEST(Renderer, RenderTilesGivesTheTilesTheBitsOfAWholeRenderAndLeavesTheRest) {
  const Scene scene(loadSceneString(kEveryShadingFeature, "s.yaml"));
  const CameraVelocity vel{Vec3(0.3, 0, 0.1), Vec3(0, 0.2, 0.05)};
  const Vec3 c0(0, -4, 2.5), c1(0.1, -3.9, 2.45);
  const Pose T0(scenes::lookAtRotation(c0, Vec3(0, 0.5, 0.5), Vec3::UnitZ()), c0);
  const Pose T1(scenes::lookAtRotation(c1, Vec3(0, 0.6, 0.5), Vec3::UnitZ()), c1);
  // Both shading paths, supersampling, and tiles that do not divide the image.
  for (const auto& [n, tile, avx2] : {std::tuple{1, 8, true}, std::tuple{1, 13, true}, std::tuple{2, 8, true},
                                      std::tuple{1, 13, false}, std::tuple{2, 13, false}}) {
    SCOPED_TRACE(::testing::Message() << "supersampling " << n << ", tiles of " << tile << " px, avx2 " << avx2);
    RendererOptions o = threads(2);
    o.supersampling = n;
    o.tile_px = tile;
    o.avx2 = avx2;
    const Renderer r(scene, radtan(97, 71), o);
    ASSERT_EQ(r.tileCount(), ((97 + tile - 1) / tile) * ((71 + tile - 1) / tile));
    const RenderOutput before = r.render(T0, &vel), after = r.render(T1, &vel);
    ASSERT_FALSE(bitEqual(before.radiance, after.radiance));
    RenderOutput out{before.radiance.clone(), before.depth.clone(), before.normal.clone(), before.flow.clone()};
    const cv::Mat alias = out.radiance;  // shared: renderTiles must copy, not write into it
    std::vector<int> tiles;
    for (int k = 0; k < r.tileCount(); k += 3) tiles.push_back(k);
    tiles.push_back(r.tileCount() - 1);  // the narrow corner tile
    RenderStats stats;
    r.renderTiles(T1, &vel, tiles.data(), tiles.size(), &out, &stats);
    EXPECT_GT(stats.camera_rays, 0u);
    EXPECT_TRUE(bitEqual(alias, before.radiance));
    for (int k = 0; k < r.tileCount(); ++k) {
      const bool rendered = std::count(tiles.begin(), tiles.end(), k) > 0;
      const RenderOutput& expected = rendered ? after : before;
      const cv::Rect rect = r.tileRect(k);
      EXPECT_TRUE(rectBitEqual(out.radiance, expected.radiance, rect)) << "tile " << k;
      EXPECT_TRUE(rectBitEqual(out.depth, expected.depth, rect)) << "tile " << k;
      EXPECT_TRUE(rectBitEqual(out.normal, expected.normal, rect)) << "tile " << k;
      EXPECT_TRUE(rectBitEqual(out.flow, expected.flow, rect)) << "tile " << k;
    }
    // Every tile re-rendered: the whole render.
    std::vector<int> all(static_cast<std::size_t>(r.tileCount()));
    for (int k = 0; k < r.tileCount(); ++k) all[static_cast<std::size_t>(k)] = k;
    r.renderTiles(T1, &vel, all.data(), all.size(), &out);
    EXPECT_TRUE(bitEqual(out.radiance, after.radiance));
    EXPECT_TRUE(bitEqual(out.flow, after.flow));
  }
  const Renderer r(scene, radtan(97, 71), threads(1));
  RenderOutput empty;
  const int tile0 = 0, bad = r.tileCount();
  EXPECT_THROW(r.renderTiles(T0, &vel, &tile0, 1, &empty), Error);  // no earlier render
  RenderOutput out = r.render(T0);
  EXPECT_THROW(r.renderTiles(T0, &vel, &tile0, 1, &out), Error);  // no flow image to write
  EXPECT_THROW(r.renderTiles(T0, nullptr, &bad, 1, &out), Error);
  EXPECT_THROW(r.tileRect(-1), Error);
}

TEST(Renderer, CameraInsideGeometryIsOneClearError) {
  const std::string yaml =
      "materials:\n  - {name: m, albedo: {type: constant, value: 0.5}}\n"
      "lights:\n  - {type: sky, radiance_w_m2_sr: 1}\n"
      "sources:\n  - {type: plane, material: m, size_m: [20, 20]}\n"
      "  - {type: box, name: boulder, material: m, position_m: [0, 0, 1], size_m: [2, 2, 2]}\n";
  const Scene scene(loadSceneString(yaml, "yard.yaml"));
  const Renderer renderer(scene, pinhole());
  try {
    renderer.render(Pose(Mat3::Identity(), Vec3(0.2, 0.1, 1.0)));
    FAIL();
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("yard.yaml:7: sources[1]"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'boulder'"), std::string::npos) << msg;
  }
}

}  // namespace
}  // namespace evio::simulator

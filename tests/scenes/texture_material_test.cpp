// Noise, textures, reflectance and lights against exact values.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "evio/core/error.h"
#include "evio/core/io/image_file.h"
#include "evio/scenes/light.h"
#include "evio/scenes/mip_map.h"
#include "evio/scenes/value_noise.h"
#include "evio/scenes/material.h"
#include "evio/scenes/noise.h"
#include "evio/scenes/texture.h"
#include "temp_dir.h"

namespace evio::scenes {
namespace {

TEST(Noise, DeterministicBoundedAndZeroOnTheLattice) {
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f p(0.37f * static_cast<float>(i), 0.11f * static_cast<float>(i % 17), 0.05f * static_cast<float>(i % 5));
    const float a = noise::gradient3(p, 7);
    EXPECT_EQ(a, noise::gradient3(p, 7));
    lo = std::min(lo, static_cast<double>(a));
    hi = std::max(hi, static_cast<double>(a));
    const double b = noise::gradient2(0.37 * i, 0.11 * (i % 17), 7);
    EXPECT_LE(std::abs(b), 1.5);
  }
  EXPECT_LT(lo, -0.3);
  EXPECT_GT(hi, 0.3);
  EXPECT_LE(std::max(-lo, hi), 1.1);
  EXPECT_EQ(noise::gradient3(Eigen::Vector3f(3, -2, 5), 1), 0.0f);
  EXPECT_EQ(noise::gradient2(3.0, -2.0, 1), 0.0);
  EXPECT_NE(noise::gradient3(Eigen::Vector3f(0.5f, 0.25f, 0.1f), 1), noise::gradient3(Eigen::Vector3f(0.5f, 0.25f, 0.1f), 2));
}

TEST(Noise, FootprintDropsFineOctaves) {
  const Eigen::Vector3f p(0.3f, 0.7f, 0.2f);
  // Footprint 0.15: octave 0 (wavelength 1 = 6.67 footprints) is faded to
  // (6.67 - 4) / 4, octave 1 (3.33 footprints) and finer are dropped.
  const float full = noise::fbm3(p, 1, 0.5f, 9);
  EXPECT_EQ(full, noise::gradient3(p, 9));
  const float lod = noise::fbm3(p, 6, 0.5f, 9, 0.15f);
  const float norm6 = (1.0f - std::pow(0.5f, 6.0f)) / 0.5f;  // Σ 0.5^o, o < 6
  EXPECT_NEAR(lod, full * (1.0f / 0.15f - 4.0f) * 0.25f / norm6, 1e-6f);
  EXPECT_EQ(noise::fbm3(p, 6, 0.5f, 9, 10.0f), 0.0f);  // everything below the footprint
}

TEST(Texture, ShapesAreBlackOnWhiteWithAntialiasedEdges) {
  TextureOptions o;
  o.type = "shapes";
  o.count = 1;
  o.shape_size_m = Vec2(0.1, 0.1);
  o.region_m = Vec2(1, 1);
  o.background = 0.9;
  o.foreground = 0.1;
  const Texture t(o, 1, "", "albedo");
  // Somewhere the single shape is: scan for the darkest point.
  float darkest = 1.0f, lightest = 0.0f;
  for (int i = 0; i < 200; ++i)
    for (int j = 0; j < 200; ++j) {
      const float a = t.evaluate(Eigen::Vector3f::Zero(), Eigen::Vector2f(i / 200.0f, j / 200.0f), 1e-4f);
      darkest = std::min(darkest, a);
      lightest = std::max(lightest, a);
    }
  EXPECT_FLOAT_EQ(darkest, 0.1f);
  EXPECT_FLOAT_EQ(lightest, 0.9f);
}

TEST(Texture, ImageIsSampledAtTexelCentres) {
  test::TempDir dir;
  cv::Mat img(2, 4, CV_8UC1);
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) img.at<unsigned char>(y, x) = static_cast<unsigned char>(20 * x + 100 * y);
  io::writePng(dir.file("t.png"), img);
  TextureOptions o;
  o.type = "image";
  o.path = "t.png";
  o.size_m = Vec2(2.0, 1.0);  // texel = 0.5 m
  const Texture t(o, 1, dir.path().string(), "albedo");
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 4; ++x) {
      const Eigen::Vector2f uv(0.5f * (static_cast<float>(x) + 0.5f), 0.5f * (static_cast<float>(y) + 0.5f));
      EXPECT_NEAR(t.evaluate(Eigen::Vector3f::Zero(), uv, 0.f), (20.0f * x + 100.0f * y) / 255.0f, 1e-6f);
    }
  // Half-way between texels 0 and 1 of row 0: the mean.
  EXPECT_NEAR(t.evaluate(Eigen::Vector3f::Zero(), Eigen::Vector2f(0.5f, 0.25f), 0.f), 10.0f / 255.0f, 1e-6f);
  o.path = "missing.png";
  try {
    Texture bad(o, 1, dir.path().string(), "scene.yaml:4: materials[0].albedo");
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("scene.yaml:4: materials[0].albedo.path"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
}

TEST(MipMap, LevelsAverageAndLookupsFilter) {
  cv::Mat img(4, 4, CV_32FC1);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) img.at<float>(y, x) = static_cast<float>((x + y) % 2);  // 1-texel checker
  const MipMap mip(img, true);
  ASSERT_EQ(mip.levels(), 3);  // 4x4, 2x2, 1x1
  EXPECT_FLOAT_EQ(mip.level(1).at<float>(0, 1), 0.5f);
  EXPECT_FLOAT_EQ(mip.level(2).at<float>(0, 0), 0.5f);
  EXPECT_FLOAT_EQ(mip.sample(1.5f, 0.5f, 0.0f), 1.0f);   // texel (1, 0) exactly
  EXPECT_FLOAT_EQ(mip.sample(1.0f, 0.5f, 0.0f), 0.5f);   // between texels 0 and 1
  EXPECT_FLOAT_EQ(mip.sample(1.5f, 0.5f, 4.0f), 0.5f);   // a 4-texel footprint sees the mean
  EXPECT_FLOAT_EQ(mip.sample(5.5f, 4.5f, 0.0f), mip.sample(1.5f, 0.5f, 0.0f));  // repeat
  const MipMap clamped(img, false);
  EXPECT_FLOAT_EQ(clamped.sample(-3.0f, 0.5f, 0.0f), 0.0f);  // clamped to texel (0, 0)
}

TEST(ValueNoise, DeterministicBoundedAndFootprintLimited) {
  const noise::ValueLattice a(5), b(5), c(6);
  float lo = 1, hi = -1;
  for (int i = 0; i < 3000; ++i) {
    const Eigen::Vector3f p(0.173f * static_cast<float>(i), 0.071f * static_cast<float>(i % 31), 0.37f);
    const float v = a.fbm(p, 6, 0.6f);
    ASSERT_EQ(v, b.fbm(p, 6, 0.6f));
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  EXPECT_LE(hi, 1.0f);
  EXPECT_GE(lo, -1.0f);
  EXPECT_GT(hi - lo, 0.5f);
  const Eigen::Vector3f p(3.3f, 1.7f, 0.2f);
  EXPECT_NE(a.value(p), c.value(p));
  EXPECT_EQ(a.value(Eigen::Vector3f(3, 1, 0)), a.value(Eigen::Vector3f(3 + 64, 1 - 64, 128)));  // period 64
  // Footprint 0.2: octave 0 (5 footprints) at weight 0.25, the rest dropped.
  const float norm = (1.0f - std::pow(0.6f, 6.0f)) / 0.4f;
  EXPECT_NEAR(a.fbm(p, 6, 0.6f, 0.2f), 0.25f * a.fbm(p, 1, 0.6f) / norm, 1e-6f);
}

TEST(ValueNoise, FourOctavesAtATimeMatchTheScalarOctaves) {
  // fbm evaluates its octaves four at a time (SSE2); the sum of the scalar
  // octaves with the same weights must agree to float rounding (bit-exact
  // at the project's flags; a fused multiply-add build may differ in the
  // last bit).
  const noise::ValueLattice a(17);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f p(0.377f * static_cast<float>(i) - 300.0f, 0.0131f * static_cast<float>(i % 97) - 0.5f,
                            -0.29f * static_cast<float>(i % 13));
    const int octaves = 1 + i % noise::ValueLattice::kMaxOctaves;
    const float footprint = i % 3 == 0 ? 0.0f : 1e-4f * static_cast<float>(i % 211);
    float norm = 0.0f, amp = 1.0f, sum = 0.0f;
    float ratio = footprint > 0.0f ? 1.0f / footprint : 1e30f;
    for (int o = 0; o < octaves; ++o, amp *= 0.6f) norm += amp;
    amp = 1.0f;
    for (int o = 0; o < octaves && ratio > 4.0f; ++o, ratio *= 0.5f, amp *= 0.6f)
      sum += (ratio < 8.0f ? (ratio - 4.0f) * 0.25f : 1.0f) * amp * a.octave(p, o);
    ASSERT_NEAR(a.fbm(p, octaves, 0.6f, footprint), sum / norm, 4e-7f) << "point " << i;
  }
}

TEST(Texture, NoiseAlbedoStaysInRangeAndVaries) {
  TextureOptions o;
  o.type = "noise";
  const Texture t(o, 3, "", "albedo");
  float lo = 1, hi = 0;
  for (int i = 0; i < 5000; ++i) {
    const float a = t.evaluate(Eigen::Vector3f(0.013f * static_cast<float>(i), 0.007f * static_cast<float>(i), 0), Eigen::Vector2f::Zero(), 0.0f);
    ASSERT_GE(a, 0.0f);
    ASSERT_LE(a, 1.0f);
    lo = std::min(lo, a);
    hi = std::max(hi, a);
  }
  EXPECT_GT(hi - lo, 0.1f);  // texture for an event camera to see
}

TEST(Reflectance, OrenNayarReducesToLambertAndIsReciprocal) {
  MaterialOptions m;
  m.name = "x";
  const Reflectance lambert(m);
  const Eigen::Vector3f n = Eigen::Vector3f::UnitZ();
  const Eigen::Vector3f wi = Eigen::Vector3f(0.3f, 0.2f, 0.9f).normalized();
  const Eigen::Vector3f wo = Eigen::Vector3f(-0.5f, 0.1f, 0.6f).normalized();
  EXPECT_FLOAT_EQ(lambert.brdfOverAlbedo(wi, wo, n.dot(wi), n.dot(wo)), 1.0f / std::numbers::pi_v<float>);
  m.model = "oren_nayar";
  m.roughness_deg = 0.0;
  const Reflectance smooth(m);
  EXPECT_FLOAT_EQ(smooth.brdfOverAlbedo(wi, wo, n.dot(wi), n.dot(wo)), 1.0f / std::numbers::pi_v<float>);
  m.roughness_deg = 30.0;
  const Reflectance rough(m);
  const double s = 30.0 * std::numbers::pi / 180.0, s2 = s * s;
  EXPECT_NEAR(rough.a(), 1.0 - 0.5 * s2 / (s2 + 0.33), 1e-7);
  EXPECT_NEAR(rough.b(), 0.45 * s2 / (s2 + 0.09), 1e-7);
  EXPECT_FLOAT_EQ(rough.brdfOverAlbedo(wi, wo, n.dot(wi), n.dot(wo)),
                  rough.brdfOverAlbedo(wo, wi, n.dot(wo), n.dot(wi)));
  // Against the trigonometric form of Oren–Nayar for in-plane directions.
  const double ti = 0.6, to = 0.9, dphi = 0.0;  // same azimuth: back-scattering side
  const Eigen::Vector3f a(static_cast<float>(std::sin(ti)), 0, static_cast<float>(std::cos(ti)));
  const Eigen::Vector3f b(static_cast<float>(std::sin(to) * std::cos(dphi)), 0, static_cast<float>(std::cos(to)));
  const double expected = (static_cast<double>(rough.a()) + static_cast<double>(rough.b()) * std::max(0.0, std::cos(dphi)) * std::sin(std::max(ti, to)) *
                                           std::tan(std::min(ti, to))) / std::numbers::pi;
  EXPECT_NEAR(rough.brdfOverAlbedo(a, b, a.z(), b.z()), expected, 1e-6);
}

TEST(Light, SunDirectionFromAzimuthAndElevation) {
  EXPECT_NEAR((sunDirection(0, 0) - Vec3(0, 1, 0)).norm(), 0.0, 1e-15);   // north
  EXPECT_NEAR((sunDirection(90, 0) - Vec3(1, 0, 0)).norm(), 0.0, 1e-15);  // east
  EXPECT_NEAR((sunDirection(123, 90) - Vec3(0, 0, 1)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(sunDirection(200, 30).norm(), 1.0, 1e-15);
}

}  // namespace
}  // namespace evio::scenes

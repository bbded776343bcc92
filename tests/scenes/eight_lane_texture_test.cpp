// The 8-lane (AVX2) texture lookups that the renderer uses against their
// scalar definitions: every lane must equal the scalar value bit for bit
// (the renderer's output must not depend on the CPU's vector width).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include <opencv2/core.hpp>

#include "evio/core/cpu_features.h"
#include "evio/core/io/image_file.h"
#include "evio/scenes/mip_map.h"
#include "evio/scenes/texture.h"
#include "evio/scenes/value_noise.h"
#include "temp_dir.h"

namespace evio::scenes {
namespace {

/// Same bits (so NaN == NaN and +0 != −0).
bool sameBits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

/// Footprints that reach every branch of the lookups: none, below and at one
/// texel, exact powers of two, a wide random range, beyond the top level, NaN.
float footprint(std::mt19937& rng) {
  std::uniform_int_distribution<int> pick(0, 9);
  std::uniform_real_distribution<float> e(-3.0f, 14.0f);
  switch (pick(rng)) {
    case 0: return 0.0f;
    case 1: return 0.5f;
    case 2: return 1.0f;
    case 3: return 4.0f;
    case 4: return 1e9f;
    case 5: return kNaN;
    default: return std::exp2(e(rng));
  }
}

TEST(MipMap, EightLaneSampleMatchesTheScalarOneBitForBit) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "this CPU has no AVX2";
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const int sizes[][2] = {{1, 1}, {1, 7}, {5, 3}, {64, 48}, {37, 129}};
  for (const auto& size : sizes)
    for (bool repeat : {true, false}) {
      SCOPED_TRACE(::testing::Message() << size[0] << " x " << size[1] << (repeat ? " repeat" : " clamp"));
      cv::Mat img(size[1], size[0], CV_32FC1);
      for (int y = 0; y < img.rows; ++y)
        for (int x = 0; x < img.cols; ++x) img.at<float>(y, x) = unit(rng);
      const MipMap mip(img, repeat);
      // Points inside and well outside the image (wrapping and clamping), and
      // exact texel centres and edges.
      std::uniform_real_distribution<float> s_of(-1.2f * static_cast<float>(size[0]), 2.2f * static_cast<float>(size[0]));
      std::uniform_real_distribution<float> t_of(-1.2f * static_cast<float>(size[1]), 2.2f * static_cast<float>(size[1]));
      int mismatches = 0;
      for (int batch = 0; batch < 500; ++batch) {
        alignas(32) float s[8], t[8], f[8], out[8];
        for (int k = 0; k < 8; ++k) {
          s[k] = batch % 5 == 0 ? std::floor(s_of(rng)) + 0.5f * static_cast<float>(k % 2) : s_of(rng);
          t[k] = t_of(rng);
          f[k] = footprint(rng);
        }
        mip.sample8Avx2(s, t, f, out);
        for (int k = 0; k < 8; ++k) mismatches += sameBits(out[k], mip.sample(s[k], t[k], f[k])) ? 0 : 1;
      }
      EXPECT_EQ(mismatches, 0);
    }
}

TEST(ValueNoise, EightLaneValueAndFbmMatchTheScalarOnesBitForBit) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "this CPU has no AVX2";
  const noise::ValueLattice lattice(11);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> coord(-300.0f, 300.0f);
  int mismatches = 0;
  for (int batch = 0; batch < 600; ++batch) {
    alignas(32) float x[8], y[8], z[8], fp[8], out[8];
    for (int k = 0; k < 8; ++k) {
      x[k] = coord(rng);
      y[k] = batch % 4 == 0 ? std::floor(coord(rng)) : coord(rng);  // exactly on lattice planes too
      z[k] = coord(rng);
      fp[k] = footprint(rng) * 1e-3f;
    }
    lattice.value8Avx2(x, y, z, out);
    for (int k = 0; k < 8; ++k)
      mismatches += sameBits(out[k], lattice.value(Eigen::Vector3f(x[k], y[k], z[k]))) ? 0 : 1;
    const int octaves = 1 + batch % 16;
    const float gain = batch % 2 ? 0.6f : 0.55f;
    lattice.fbm8Avx2(x, y, z, octaves, gain, fp, out);
    for (int k = 0; k < 8; ++k)
      mismatches += sameBits(out[k], lattice.fbm(Eigen::Vector3f(x[k], y[k], z[k]), octaves, gain, fp[k])) ? 0 : 1;
  }
  EXPECT_EQ(mismatches, 0);
}

TEST(Texture, EightLaneEvaluateMatchesTheScalarOneBitForBit) {
  if (!cpuHasAvx2()) GTEST_SKIP() << "this CPU has no AVX2";
  test::TempDir dir;
  cv::Mat img(13, 21, CV_8UC1);
  cv::randu(img, 0, 255);
  io::writePng(dir.file("t.png"), img);
  std::vector<TextureOptions> kinds(7);
  kinds[0].type = "constant";
  kinds[1].type = "checker";
  kinds[2].type = "noise";
  kinds[3].type = "image";
  kinds[3].path = "t.png";
  kinds[3].size_m = Vec2(0.7, 0.4);
  kinds[3].offset_m = Vec2(0.1, -0.2);
  kinds[3].gain = 1.3;  // clamps
  kinds[4] = kinds[3];
  kinds[4].repeat = false;
  kinds[5].type = "shapes";
  kinds[5].region_m = Vec2(1.0, 0.6);
  kinds[6].type = "collage";
  kinds[6].region_m = Vec2(0.8, 0.8);
  kinds[6].count = 30;
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> coord(-2.0f, 3.0f);
  for (const TextureOptions& o : kinds) {
    SCOPED_TRACE(o.type + (o.repeat ? "" : " (clamped)"));
    const Texture tex(o, 9, dir.path().string(), "albedo");
    int mismatches = 0;
    for (int batch = 0; batch < 400; ++batch) {
      alignas(32) float px[8], py[8], pz[8], u[8], v[8], fp[8], out[8];
      for (int k = 0; k < 8; ++k) {
        px[k] = 10.0f * coord(rng);
        py[k] = 10.0f * coord(rng);
        pz[k] = coord(rng);
        u[k] = coord(rng);  // inside and outside the baked region and the image
        v[k] = coord(rng);
        fp[k] = footprint(rng) * 1e-3f;
      }
      tex.evaluate8Avx2(px, py, pz, u, v, fp, out);
      for (int k = 0; k < 8; ++k)
        mismatches += sameBits(out[k], tex.evaluate(Eigen::Vector3f(px[k], py[k], pz[k]),
                                                    Eigen::Vector2f(u[k], v[k]), fp[k]))
                          ? 0
                          : 1;
    }
    EXPECT_EQ(mismatches, 0);
  }
}

}  // namespace
}  // namespace evio::scenes

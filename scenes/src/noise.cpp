#include "evio/scenes/noise.h"

#include <cmath>

namespace evio::noise {

namespace {

inline std::uint32_t mix(std::uint32_t h) {
  // Final avalanche of MurmurHash3.
  h ^= h >> 16;
  h *= 0x85ebca6bU;
  h ^= h >> 13;
  h *= 0xc2b2ae35U;
  h ^= h >> 16;
  return h;
}

inline double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }
inline float fadef(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }

inline int floorInt(double x) {
  const int i = static_cast<int>(x);
  return (x < static_cast<double>(i)) ? i - 1 : i;
}
inline int floorIntf(float x) {
  const int i = static_cast<int>(x);
  return (x < static_cast<float>(i)) ? i - 1 : i;
}

// 16 unit directions in the plane, for 2-D gradients.
constexpr double kDir2[16][2] = {
    {1.0, 0.0},         {0.92387953, 0.38268343},   {0.70710678, 0.70710678},
    {0.38268343, 0.92387953},   {0.0, 1.0},         {-0.38268343, 0.92387953},
    {-0.70710678, 0.70710678},  {-0.92387953, 0.38268343},  {-1.0, 0.0},
    {-0.92387953, -0.38268343}, {-0.70710678, -0.70710678}, {-0.38268343, -0.92387953},
    {0.0, -1.0},        {0.38268343, -0.92387953},  {0.70710678, -0.70710678},
    {0.92387953, -0.38268343}};

inline double grad2(std::uint32_t h, double x, double y) {
  const auto& d = kDir2[h & 15U];
  return d[0] * x + d[1] * y;
}

// Perlin's 12 cube-edge gradients (plus 4 repeats to make 16).
inline float grad3(std::uint32_t h, float x, float y, float z) {
  switch (h & 15U) {
    case 0: return x + y;
    case 1: return -x + y;
    case 2: return x - y;
    case 3: return -x - y;
    case 4: return x + z;
    case 5: return -x + z;
    case 6: return x - z;
    case 7: return -x - z;
    case 8: return y + z;
    case 9: return -y + z;
    case 10: return y - z;
    case 11: return -y - z;
    case 12: return x + y;
    case 13: return -y + z;
    case 14: return -x + y;
    default: return -y - z;
  }
}

/// Lattice hash for gradient3: one avalanche per corner over per-axis
/// products (cheaper than hash(); used where speed matters, per pixel).
inline std::uint32_t corner(std::uint32_t hx, std::uint32_t hy, std::uint32_t hz) {
  std::uint32_t h = hx ^ hy ^ hz;
  h ^= h >> 15U;
  h *= 0x2c1b3c6dU;
  h ^= h >> 12U;
  h *= 0x297a2d39U;
  h ^= h >> 15U;
  return h;
}

}  // namespace

std::uint32_t hash(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t seed) {
  std::uint32_t h = seed ^ 0x9e3779b9U;
  h = mix(h ^ static_cast<std::uint32_t>(x) * 0x8da6b343U);
  h = mix(h ^ static_cast<std::uint32_t>(y) * 0xd8163841U);
  h = mix(h ^ static_cast<std::uint32_t>(z) * 0xcb1ab31fU);
  return h;
}

double gradient2(double x, double y, std::uint32_t seed) {
  const int ix = floorInt(x), iy = floorInt(y);
  const double fx = x - ix, fy = y - iy;
  const double u = fade(fx), v = fade(fy);
  const double n00 = grad2(hash(ix, iy, 0, seed), fx, fy);
  const double n10 = grad2(hash(ix + 1, iy, 0, seed), fx - 1.0, fy);
  const double n01 = grad2(hash(ix, iy + 1, 0, seed), fx, fy - 1.0);
  const double n11 = grad2(hash(ix + 1, iy + 1, 0, seed), fx - 1.0, fy - 1.0);
  const double a = n00 + u * (n10 - n00);
  const double b = n01 + u * (n11 - n01);
  return (a + v * (b - a)) * 1.41421356;  // scale the ±√½ range to about ±1
}

float gradient3(const Eigen::Vector3f& p, std::uint32_t seed) {
  const int ix = floorIntf(p.x()), iy = floorIntf(p.y()), iz = floorIntf(p.z());
  const float fx = p.x() - static_cast<float>(ix);
  const float fy = p.y() - static_cast<float>(iy);
  const float fz = p.z() - static_cast<float>(iz);
  const float u = fadef(fx), v = fadef(fy), w = fadef(fz);
  constexpr std::uint32_t kX = 0x8da6b343U, kY = 0xd8163841U, kZ = 0xcb1ab31fU;
  const std::uint32_t x0 = (static_cast<std::uint32_t>(ix) * kX) ^ seed;
  const std::uint32_t x1 = (static_cast<std::uint32_t>(ix + 1) * kX) ^ seed;
  const std::uint32_t y0 = static_cast<std::uint32_t>(iy) * kY, y1 = static_cast<std::uint32_t>(iy + 1) * kY;
  const std::uint32_t z0 = static_cast<std::uint32_t>(iz) * kZ, z1 = static_cast<std::uint32_t>(iz + 1) * kZ;
  const float n000 = grad3(corner(x0, y0, z0), fx, fy, fz);
  const float n100 = grad3(corner(x1, y0, z0), fx - 1.0f, fy, fz);
  const float n010 = grad3(corner(x0, y1, z0), fx, fy - 1.0f, fz);
  const float n110 = grad3(corner(x1, y1, z0), fx - 1.0f, fy - 1.0f, fz);
  const float n001 = grad3(corner(x0, y0, z1), fx, fy, fz - 1.0f);
  const float n101 = grad3(corner(x1, y0, z1), fx - 1.0f, fy, fz - 1.0f);
  const float n011 = grad3(corner(x0, y1, z1), fx, fy - 1.0f, fz - 1.0f);
  const float n111 = grad3(corner(x1, y1, z1), fx - 1.0f, fy - 1.0f, fz - 1.0f);
  const float x00 = n000 + u * (n100 - n000);
  const float x10 = n010 + u * (n110 - n010);
  const float x01 = n001 + u * (n101 - n001);
  const float x11 = n011 + u * (n111 - n011);
  const float y00 = x00 + v * (x10 - x00);
  const float y11 = x01 + v * (x11 - x01);
  return y00 + w * (y11 - y00);
}

double fbm2(double x, double y, int octaves, double gain, std::uint32_t seed, double lacunarity) {
  double sum = 0.0, norm = 0.0, amp = 1.0, freq = 1.0;
  for (int o = 0; o < octaves; ++o) {
    // A per-octave offset decorrelates the octaves' lattices.
    const double off = 17.31 * o;
    sum += amp * gradient2(x * freq + off, y * freq - off, seed + static_cast<std::uint32_t>(o));
    norm += amp;
    amp *= gain;
    freq *= lacunarity;
  }
  return norm > 0.0 ? sum / norm : 0.0;
}

float fbm3(const Eigen::Vector3f& p, int octaves, float gain, std::uint32_t seed, float footprint) {
  float norm = 0.0f;
  {
    float a = 1.0f;
    for (int o = 0; o < octaves; ++o, a *= gain) norm += a;
  }
  float sum = 0.0f, amp = 1.0f, freq = 1.0f;
  for (int o = 0; o < octaves; ++o) {
    float weight = 1.0f;
    if (footprint > 0.0f) {
      // wavelength 1/freq in footprints; fade out between 8 and 4.
      const float ratio = 1.0f / (freq * footprint);
      if (ratio <= 4.0f) break;
      if (ratio < 8.0f) weight = (ratio - 4.0f) * 0.25f;
    }
    const float off = 17.31f * static_cast<float>(o);
    sum += weight * amp *
           gradient3(p * freq + Eigen::Vector3f(off, -off, 0.5f * off), seed + static_cast<std::uint32_t>(o));
    amp *= gain;
    freq *= 2.0f;
  }
  return norm > 0.0f ? sum / norm : 0.0f;
}

}  // namespace evio::noise

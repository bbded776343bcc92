#include "evio/scenes/value_noise.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "evio/core/random_stream.h"

namespace evio::noise {

namespace {
inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
inline int floorInt(float x) {
  const int i = static_cast<int>(x);
  return (x < static_cast<float>(i)) ? i - 1 : i;
}
}  // namespace

ValueLattice::ValueLattice(std::uint64_t seed) : v_(static_cast<std::size_t>(kSize * kSize * kSize)) {
  RandomStream rng(seed, "value lattice");
  // 8-bit levels in [−1, 1], as a compact table would hold them.
  for (auto& x : v_) x = static_cast<std::int8_t>(static_cast<int>(rng.uniformInt(255)) - 127);
  for (int o = 0; o < kMaxOctaves; ++o) {
    const Eigen::Vector3f axis = Eigen::Vector3f(static_cast<float>(rng.uniform(-1.0, 1.0)),
                                                 static_cast<float>(rng.uniform(-1.0, 1.0)), 1.0f)
                                     .normalized();
    const float angle = static_cast<float>(rng.uniform(0.3, 2.0 * std::numbers::pi - 0.3));
    const Eigen::Matrix3f R = o == 0 ? Eigen::Matrix3f::Identity() : Eigen::AngleAxisf(angle, axis).toRotationMatrix();
    rotation_[static_cast<std::size_t>(o)] = std::ldexp(1.0f, o) * R;
    offset_[static_cast<std::size_t>(o)] = Eigen::Vector3f(static_cast<float>(rng.uniform(0.0, kSize)),
                                                           static_cast<float>(rng.uniform(0.0, kSize)),
                                                           static_cast<float>(rng.uniform(0.0, kSize)));
  }
}

float ValueLattice::value(const Eigen::Vector3f& p) const {
  const int ix = floorInt(p.x()), iy = floorInt(p.y()), iz = floorInt(p.z());
  const float u = fade(p.x() - static_cast<float>(ix));
  const float v = fade(p.y() - static_cast<float>(iy));
  const float w = fade(p.z() - static_cast<float>(iz));
  constexpr int m = kSize - 1;
  const int x0 = ix & m, x1 = (ix + 1) & m;
  const int y0 = (iy & m) * kSize, y1 = ((iy + 1) & m) * kSize;
  const int z0 = (iz & m) * kSize * kSize, z1 = ((iz + 1) & m) * kSize * kSize;
  const std::int8_t* t = v_.data();
  const auto at = [t](int i) { return static_cast<float>(t[i]); };
  const float a00 = at(z0 + y0 + x0) + u * (at(z0 + y0 + x1) - at(z0 + y0 + x0));
  const float a10 = at(z0 + y1 + x0) + u * (at(z0 + y1 + x1) - at(z0 + y1 + x0));
  const float a01 = at(z1 + y0 + x0) + u * (at(z1 + y0 + x1) - at(z1 + y0 + x0));
  const float a11 = at(z1 + y1 + x0) + u * (at(z1 + y1 + x1) - at(z1 + y1 + x0));
  const float b0 = a00 + v * (a10 - a00);
  const float b1 = a01 + v * (a11 - a01);
  return (b0 + w * (b1 - b0)) * (1.0f / 127.0f);
}

float ValueLattice::fbm(const Eigen::Vector3f& p, int octaves, float gain, float footprint) const {
  if (octaves > kMaxOctaves) octaves = kMaxOctaves;
  float norm = 0.0f;
  {
    float a = 1.0f;
    for (int o = 0; o < octaves; ++o, a *= gain) norm += a;
  }
  // ratio = wavelength / footprint = 1 / (2^o footprint).
  float ratio = footprint > 0.0f ? 1.0f / footprint : 1e30f;
  float sum = 0.0f, amp = 1.0f;
  for (int o = 0; o < octaves; ++o, ratio *= 0.5f, amp *= gain) {
    if (ratio <= 4.0f) break;
    const float weight = ratio < 8.0f ? (ratio - 4.0f) * 0.25f : 1.0f;
    const auto k = static_cast<std::size_t>(o);
    sum += weight * amp * value(rotation_[k] * p + offset_[k]);
  }
  return sum / norm;
}

}  // namespace evio::noise

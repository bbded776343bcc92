#pragma once
/// @file value_noise.h
/// Fast multi-octave 3-D value noise for per-pixel textures.
///
/// A lattice of 64³ pseudo-random values v ∈ [−1, 1] (255 levels, from
/// RandomStream(seed, "value lattice")), periodic with period 64 cells, is
/// interpolated with the quintic fade w(t) = 6t⁵ − 15t⁴ + 10t³ per axis:
///   n(p) = Σ_corners w(·) v[⌊p⌋ + corner].
/// Octave o samples n at R_o (2^o p) + t_o, with a fixed rotation R_o and
/// offset t_o per octave, so that the lattice axes and the period of one
/// octave do not line up with the others' (no visible grid or repetition).
///   fbm(p) = Σ_o gain^o · weight_o · n(R_o 2^o p + t_o) / Σ_o gain^o,
/// with the level-of-detail weights of noise::fbm3 (octaves of wavelength
/// at most 4 footprints dropped, faded in between 4 and 8). One octave costs
/// 8 table reads and 7 interpolations, a few times less than gradient noise.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

namespace evio::noise {

class ValueLattice {
 public:
  static constexpr int kSize = 64;       ///< lattice period (cells per axis)
  static constexpr int kMaxOctaves = 16;

  explicit ValueLattice(std::uint64_t seed);

  /// Single-octave value noise at p (lattice units), in [−1, 1].
  float value(const Eigen::Vector3f& p) const;

  /// Multi-octave value noise (see the file comment); about [−1, 1].
  float fbm(const Eigen::Vector3f& p, int octaves, float gain, float footprint = 0.0f) const;

  /// value() at eight points (x[k], y[k], z[k]) and fbm() at eight points
  /// with footprint[k], with AVX2 across the points (only on a CPU that has
  /// it): bit for bit the scalar results.
  void value8Avx2(const float* x, const float* y, const float* z, float* out) const;
  void fbm8Avx2(const float* x, const float* y, const float* z, int octaves, float gain, const float* footprint,
                float* out) const;

  /// Octave o alone, n(R_o 2^o p + t_o), through the scalar value(): the
  /// reference for fbm's terms, which are evaluated four at a time.
  float octave(const Eigen::Vector3f& p, int o) const {
    const auto k = static_cast<std::size_t>(o);
    return value(rotation_[k] * p + offset_[k]);
  }

 private:
  /// n(R_o 2^o p + t_o) for the count ≤ 4 octaves o = first, first + 1, ...
  /// into out[0, count), side by side with SSE2 (octave() otherwise); the
  /// same float operations in the same order as octave(), so bit-identical
  /// to it at the project's flags.
  void octaveValues(const Eigen::Vector3f& p, int first, int count, float* out) const;
  /// The same for count ≤ 8 octaves with AVX2 (only when avx2_).
  void octaveValues8(const Eigen::Vector3f& p, int first, int count, float* out) const;

  bool avx2_ = false;  ///< the CPU has AVX2 (x86-64 GCC/Clang builds check at construction)

  std::vector<std::int8_t> v_;  ///< kSize³ values × 127, x fastest (256 KiB: stays in cache), + 3 bytes of padding
  /// The same values in rows of kSize + 1 (x = kSize repeats x = 0), + 3
  /// bytes of padding: the AVX2 lookups read both x neighbours in one gather.
  std::vector<std::int8_t> pairs_;
  std::array<Eigen::Matrix3f, kMaxOctaves> rotation_;  ///< 2^o R_o
  std::array<Eigen::Vector3f, kMaxOctaves> offset_;
  /// The same, one row per matrix entry (3 i + j) or offset component,
  /// one column per octave (for octaveValues).
  alignas(16) std::array<std::array<float, kMaxOctaves>, 9> rotation_soa_{};
  alignas(16) std::array<std::array<float, kMaxOctaves>, 3> offset_soa_{};
};

namespace detail {
inline float fade(float t) { return t * t * t * (t * (t * 6.0f - 15.0f) + 10.0f); }
inline int floorInt(float x) {
  const int i = static_cast<int>(x);
  return (x < static_cast<float>(i)) ? i - 1 : i;
}
}  // namespace detail

// The lookup, inline for the texture's inner loop.

inline float ValueLattice::value(const Eigen::Vector3f& p) const {
  const int ix = detail::floorInt(p.x()), iy = detail::floorInt(p.y()), iz = detail::floorInt(p.z());
  const float u = detail::fade(p.x() - static_cast<float>(ix));
  const float v = detail::fade(p.y() - static_cast<float>(iy));
  const float w = detail::fade(p.z() - static_cast<float>(iz));
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

}  // namespace evio::noise

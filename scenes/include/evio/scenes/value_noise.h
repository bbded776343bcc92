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

 private:
  std::vector<std::int8_t> v_;  ///< kSize³ values × 127, x fastest (256 KiB: stays in cache)
  std::array<Eigen::Matrix3f, kMaxOctaves> rotation_;  ///< 2^o R_o
  std::array<Eigen::Vector3f, kMaxOctaves> offset_;
};

}  // namespace evio::noise

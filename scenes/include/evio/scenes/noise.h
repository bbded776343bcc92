#pragma once
/// @file noise.h
/// Deterministic procedural noise for terrain and textures. No RNG state: a
/// value is a pure function of (position, seed), so a static scene is the
/// same at every render, on every platform and whatever the thread count.
///
/// Gradient noise (Perlin 2002, "Improving noise", SIGGRAPH): pseudo-random
/// unit gradients g_k at integer lattice points, hashed from (lattice index,
/// seed); noise(p) = Σ_k w_k(p) g_k·(p − k) with the quintic fade
/// w(t) = 6t⁵ − 15t⁴ + 10t³ per axis. Range about [−1, 1], zero at lattice
/// points, one lattice cell = one unit of p.
///
/// Fractal Brownian motion (multi-octave):
///   fbm(p) = Σ_{o=0}^{n−1} gain^o · noise(lacunarity^o · p + offset_o) / Σ gain^o.

#include <cstdint>

#include <Eigen/Core>

namespace evio::noise {

/// 32-bit hash of three integers and a seed (avalanching integer mix).
std::uint32_t hash(std::int32_t x, std::int32_t y, std::int32_t z, std::uint32_t seed);

/// Uniform in [0, 1) from a hash.
inline float unit(std::uint32_t h) { return static_cast<float>(h >> 8) * (1.0f / 16777216.0f); }

/// 2-D gradient noise in double precision (terrain heights).
double gradient2(double x, double y, std::uint32_t seed);

/// 3-D gradient noise in single precision (textures, rock shapes).
float gradient3(const Eigen::Vector3f& p, std::uint32_t seed);

/// Multi-octave 2-D gradient noise, normalised to about [−1, 1].
double fbm2(double x, double y, int octaves, double gain, std::uint32_t seed,
            double lacunarity = 2.0);

/// Multi-octave 3-D gradient noise with level of detail: octaves whose
/// wavelength (1 / frequency, in units of p) is at most 4 · footprint are
/// left out and those between 4 and 8 footprints faded in linearly, so that
/// detail finer than a few pixels does not alias (and flicker into false
/// events). footprint = 0 keeps every octave. Normalised by the full
/// Σ gain^o (the value shrinks towards 0 as detail is dropped).
float fbm3(const Eigen::Vector3f& p, int octaves, float gain, std::uint32_t seed,
           float footprint = 0.0f);

/// Hermite smoothstep: 0 for x <= e0, 1 for x >= e1, 3t² − 2t³ in between.
inline float smoothstep(float e0, float e1, float x) {
  float t = (x - e0) / (e1 - e0);
  t = t < 0.0f ? 0.0f : (t > 1.0f ? 1.0f : t);
  return t * t * (3.0f - 2.0f * t);
}

}  // namespace evio::noise

#pragma once
/// @file counter_rng.h
/// Counter-based random draws: every draw is a pure function of
/// (stream key, pixel, counter), so the numbers a pixel gets do not depend on
/// the order in which pixels are processed or on the number of threads (the
/// idea of PBRT's Hash(pixel, seed) and of Random123's counter-based
/// generators; the mixer here is the splitmix64 finaliser).
///
///   key = streamSeed(seed, "stream name")          (random_stream.h)
///   u   = mix(mix(key ^ mix(pixel + φ)) + counter·φ') → 53-bit uniform
///
/// A pixel's k-th draw of a stream uses counter k; draws that need two
/// uniforms (normal) use counters 2k and 2k + 1 of a derived key.

#include <cmath>
#include <cstdint>
#include <numbers>

#include "evio/core/random_stream.h"

namespace evio::simulator {

/// The splitmix64 finaliser: a bijective 64-bit mixer.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

/// 64 random bits for (key, pixel, counter).
constexpr std::uint64_t counterHash(std::uint64_t key, std::uint64_t pixel, std::uint64_t counter) {
  const std::uint64_t a = mix64(key ^ mix64(pixel + 0x9E3779B97F4A7C15ull));
  return mix64(a + (counter + 1) * 0xD1B54A32D192ED03ull);
}

/// Uniform in [0, 1) with 53 bits.
inline double counterUniform(std::uint64_t key, std::uint64_t pixel, std::uint64_t counter) {
  return static_cast<double>(counterHash(key, pixel, counter) >> 11) * 0x1.0p-53;
}

/// Uniform in (0, 1]: never 0, safe under log.
inline double counterUniformPositive(std::uint64_t key, std::uint64_t pixel, std::uint64_t counter) {
  return static_cast<double>((counterHash(key, pixel, counter) >> 11) + 1) * 0x1.0p-53;
}

/// Standard normal by Box–Muller from counters 2k and 2k + 1.
inline double counterNormal(std::uint64_t key, std::uint64_t pixel, std::uint64_t counter) {
  const double u1 = counterUniformPositive(key, pixel, 2 * counter);
  const double u2 = counterUniform(key, pixel, 2 * counter + 1);
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

/// Exponential with rate 1 (mean 1).
inline double counterExponential(std::uint64_t key, std::uint64_t pixel, std::uint64_t counter) {
  return -std::log(counterUniformPositive(key, pixel, counter));
}

/// The key of a named stream of a run (same hash as RandomStream's seed).
inline std::uint64_t counterKey(std::uint64_t seed, std::string_view stream) {
  return streamSeed(seed, stream);
}

}  // namespace evio::simulator

#pragma once
/// @file random_stream.h
/// Seeded random streams. There is no global RNG: every noise source owns a
/// RandomStream seeded by hash(seed, source name), so adding a source never
/// changes the numbers another source draws. The generator (xoshiro256**) and
/// the distributions are implemented here, not taken from <random>, so the
/// sequence is identical on every standard library and platform.

#include <cstdint>
#include <string_view>

namespace evio {

/// 64-bit hash of (seed, name): FNV-1a over the name, mixed with the seed by
/// splitmix64. Stable across versions; changing it changes every sequence.
std::uint64_t streamSeed(std::uint64_t seed, std::string_view name);

class RandomStream {
 public:
  /// A stream for noise source `name` of a run with `seed`.
  RandomStream(std::uint64_t seed, std::string_view name);
  /// A stream from a raw 64-bit state seed.
  explicit RandomStream(std::uint64_t raw_seed);

  /// Next raw 64-bit value (xoshiro256**). Satisfies UniformRandomBitGenerator.
  std::uint64_t operator()();
  using result_type = std::uint64_t;
  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return ~result_type{0}; }

  /// Uniform in [0, 1) with 53 random bits.
  double uniform();
  /// Uniform in [a, b).
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  /// Uniform integer in [0, n), n > 0 (Lemire's unbiased method).
  std::uint64_t uniformInt(std::uint64_t n);
  /// Standard normal N(0, 1) (Marsaglia polar method; the spare value is kept).
  double normal();
  /// Normal N(mean, sigma²).
  double normal(double mean, double sigma) { return mean + sigma * normal(); }
  /// Exponential with rate λ > 0 (mean 1/λ).
  double exponential(double rate);
  /// Bernoulli(p).
  bool bernoulli(double p) { return uniform() < p; }

 private:
  std::uint64_t s_[4];
  bool has_spare_ = false;
  double spare_ = 0.0;
};

}  // namespace evio

#pragma once
/// @file motion_primitives.h
/// Smooth scalar building blocks of the preset trajectories, evaluated as
/// Taylor series of time (taylor.h) so their derivatives are exact. Every
/// block is C∞.

#include <array>
#include <numbers>

#include "evio/core/random_stream.h"
#include "evio/trajectories/taylor.h"

namespace evio::motion {

/// A C∞ smoothstep: S(u) = f(u) / (f(u) + f(1 − u)) with f(x) = exp(−1/x)
/// for x > 0 (0 otherwise). S = 0 for u ≤ 0, 1 for u ≥ 1, S(½) = ½, every
/// derivative vanishes at both ends, peak slope S'(½) = 2. Being C∞ (unlike
/// polynomial smoothsteps, whose k-th derivative jumps at the ends), the
/// IMU, its derivatives and any integration scheme see no kink at a phase
/// change. Below u = 1/700 (and above 1 − 1/700) f(u) < e⁻⁷⁰⁰ and the step is
/// taken as exactly 0 (1); the neglected terms are below 1e-280.
template <int N>
taylor::Scalar<N> smoothStep(const taylor::Scalar<N>& u) {
  constexpr double kFlat = 1.0 / 700.0;
  if (u.c[0] <= kFlat) return taylor::Scalar<N>::constant(0.0);
  if (u.c[0] >= 1.0 - kFlat) return taylor::Scalar<N>::constant(1.0);
  const auto one = taylor::Scalar<N>::constant(1.0);
  const taylor::Scalar<N> f0 = taylor::exp(-(one / u));
  const taylor::Scalar<N> f1 = taylor::exp(-(one / (1.0 - u)));
  return f0 / (f0 + f1);
}

/// max |S''(u)| = 9.84104230183114…, at u ≈ 0.21826 and 1 − 0.21826 (the
/// root of S''' found to 40 digits with mpmath): a Transition of `delta`
/// over T seconds peaks at |delta| · 9.841 / T² in acceleration.
inline constexpr double kSmoothStepPeakSecondDerivative = 9.8410423018311447;

/// A smooth change of `delta` that starts at `start_s` and lasts `duration_s`:
/// x(t) = delta · S((t − start_s) / duration_s).
struct Transition {
  double start_s = 0.0;
  double duration_s = 1.0;
  double delta = 1.0;

  template <int N>
  taylor::Scalar<N> operator()(const taylor::Scalar<N>& t) const {
    return delta * smoothStep((1.0 / duration_s) * (t - start_s));
  }
  double end_s() const { return start_s + duration_s; }
};

/// A bounded random wobble x(t) = Σ_j w_j sin(2π f_j t + φ_j) with weights
/// summing to 1, so |x(t)| ≤ 1 for all t (C∞). Frequencies are drawn uniformly
/// in [f_min, f_max] Hz and phases uniformly in [0, 2π).
class Wobble {
 public:
  Wobble() = default;
  Wobble(RandomStream& rng, double f_min_hz, double f_max_hz) {
    for (std::size_t j = 0; j < kTerms; ++j) {
      freq_hz_[j] = rng.uniform(f_min_hz, f_max_hz);
      phase_[j] = rng.uniform(0.0, 2.0 * std::numbers::pi);
    }
  }

  template <int N>
  taylor::Scalar<N> operator()(const taylor::Scalar<N>& t) const {
    taylor::Scalar<N> x;
    for (std::size_t j = 0; j < kTerms; ++j)
      x = x + kWeights[j] * taylor::sin((2.0 * std::numbers::pi * freq_hz_[j]) * t + phase_[j]);
    return x;
  }

 private:
  static constexpr std::size_t kTerms = 3;
  static constexpr std::array<double, kTerms> kWeights = {0.5, 0.3, 0.2};
  std::array<double, kTerms> freq_hz_{};
  std::array<double, kTerms> phase_{};
};

/// A chirped oscillation whose amplitude and frequency ramp linearly over
/// [0, T]:  x(t) = A(t) sin(Φ(t) + φ0),  A(t) = A0 + (A1 − A0) t/T,
/// Φ(t) = 2π ∫₀ᵗ f = 2π (f0 t + (f1 − f0) t² / (2T)). C∞; |x| ≤ max(A0, A1).
/// With onset_s > 0 the oscillation fades in from rest: x(t) · S(t / onset_s)
/// (S the C∞ smoothstep), so x and all its derivatives are 0 at t = 0.
struct Chirp {
  double amplitude_start = 0.0;
  double amplitude_end = 0.0;
  double frequency_start_hz = 0.0;
  double frequency_end_hz = 0.0;
  double duration_s = 1.0;
  double phase_rad = 0.0;
  double onset_s = 0.0;

  template <int N>
  taylor::Scalar<N> operator()(const taylor::Scalar<N>& t) const {
    if (onset_s > 0.0) return oscillation(t) * smoothStep((1.0 / onset_s) * t);
    return oscillation(t);
  }

  template <int N>
  taylor::Scalar<N> oscillation(const taylor::Scalar<N>& t) const {
    const double T = duration_s;
    const taylor::Scalar<N> amplitude = amplitude_start + ((amplitude_end - amplitude_start) / T) * t;
    const taylor::Scalar<N> phase =
        (2.0 * std::numbers::pi) *
        (frequency_start_hz * t + ((frequency_end_hz - frequency_start_hz) / (2.0 * T)) * (t * t));
    return amplitude * taylor::sin(phase + phase_rad);
  }
};

}  // namespace evio::motion

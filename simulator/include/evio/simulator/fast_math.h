#pragma once
/// @file fast_math.h
/// Branch-free float log and exp that the compiler vectorises in plain loops
/// (std::log / std::exp are library calls that stop vectorisation). Used by
/// the event camera's per-pixel hot loop; accuracy is stated per function and
/// checked in tests/simulator/event_camera_test.cpp.

#include <bit>
#include <cstdint>

namespace evio::simulator {

/// Natural log of a positive, finite, normal float. Range reduction
/// x = 2^e · m with m ∈ [√½, √2), then log m = 2 atanh(s), s = (m−1)/(m+1),
/// by its odd series to s⁹ (|s| ≤ 0.1716, truncation < 4·10⁻¹⁰). Absolute error
/// below 2·10⁻⁷ · max(1, |log x|) (float rounding).
inline float fastLog(float x) {
  const auto bits = std::bit_cast<std::int32_t>(x);
  const std::int32_t shifted = bits - 0x3F3504F3;  // bits of √½
  const std::int32_t e = shifted >> 23;            // arithmetic shift: exponent relative to √½
  const float m = std::bit_cast<float>(bits - (e << 23));
  const float s = (m - 1.0f) / (m + 1.0f);
  const float s2 = s * s;
  const float poly =
      1.0f + s2 * (1.0f / 3.0f + s2 * (1.0f / 5.0f + s2 * (1.0f / 7.0f + s2 * (1.0f / 9.0f))));
  return static_cast<float>(e) * 0.693147180559945f + 2.0f * s * poly;
}

/// e^x for x ≤ 0 (x < −87 gives 0 after clamping to −87, e^−87 ≈ 1.6·10⁻³⁸).
/// x = n ln2 + r with |r| ≤ ½ ln2 (Cody–Waite split of ln2), e^r by its
/// Taylor polynomial to r⁷ (truncation < 2·10⁻⁸), scaled by 2^n through the
/// exponent bits. Relative error below 3·10⁻⁷.
inline float fastExpNonPositive(float x) {
  x = x < -87.0f ? -87.0f : x;
  const float n = static_cast<float>(static_cast<std::int32_t>(x * 1.44269504088896f - 0.5f));
  const float r = (x - n * 0.693145751953125f) - n * 1.428606765330187e-06f;
  const float p =
      1.0f + r * (1.0f + r * (0.5f + r * (1.0f / 6.0f +
                 r * (1.0f / 24.0f + r * (1.0f / 120.0f + r * (1.0f / 720.0f + r * (1.0f / 5040.0f)))))));
  const std::int32_t scale = (static_cast<std::int32_t>(n) + 127) << 23;
  return p * std::bit_cast<float>(scale);
}

}  // namespace evio::simulator

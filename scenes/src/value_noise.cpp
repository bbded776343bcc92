#include "evio/scenes/value_noise.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "avx2.h"
#if defined(EVIO_SCENES_AVX2)
#define EVIO_VALUE_NOISE_AVX2 1  // an AVX2 path chosen at run time
#endif

#include <Eigen/Geometry>

#include "evio/core/cpu_features.h"
#include "evio/core/random_stream.h"

namespace evio::noise {


ValueLattice::ValueLattice(std::uint64_t seed) : v_(static_cast<std::size_t>(kSize * kSize * kSize)) {
  RandomStream rng(seed, "value lattice");
  // 8-bit levels in [−1, 1], as a compact table would hold them.
  for (auto& x : v_) x = static_cast<std::int8_t>(static_cast<int>(rng.uniformInt(255)) - 127);
  v_.resize(v_.size() + 3, 0);  // 4-byte gathers at the last entry stay inside
  // Rows of kSize + 1 entries, the last one a copy of the row's first (x = 0
  // follows x = kSize − 1): one 4-byte gather at x holds the values at x and
  // at x + 1 (mod kSize). + 3 bytes: the gathers at the last entry stay inside.
  constexpr std::size_t kRow = kSize + 1;
  pairs_.assign(kRow * kSize * kSize + 3, 0);
  for (std::size_t zy = 0; zy < static_cast<std::size_t>(kSize * kSize); ++zy)
    for (std::size_t x = 0; x < kRow; ++x) pairs_[zy * kRow + x] = v_[zy * kSize + x % kSize];
#if defined(EVIO_VALUE_NOISE_AVX2)
  avx2_ = cpuHasAvx2();
#endif
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
  for (std::size_t o = 0; o < static_cast<std::size_t>(kMaxOctaves); ++o)
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) rotation_soa_[static_cast<std::size_t>(3 * i + j)][o] = rotation_[o](i, j);
      offset_soa_[static_cast<std::size_t>(i)][o] = offset_[o][i];
    }
}

void ValueLattice::octaveValues(const Eigen::Vector3f& p, int first, int count, float* out) const {
#if defined(__SSE2__)
  const __m128 px = _mm_set1_ps(p.x()), py = _mm_set1_ps(p.y()), pz = _mm_set1_ps(p.z());
  const __m128i m = _mm_set1_epi32(kSize - 1), one = _mm_set1_epi32(1);
  const std::int8_t* t = v_.data();
  {
    const int g = first;
    const auto row = [g](const std::array<float, kMaxOctaves>& r) { return _mm_load_ps(r.data() + g); };
    __m128 q[3];
    for (int i = 0; i < 3; ++i)  // (R p)_i + t_i, summed in Eigen's order: (r_i0 x + (r_i1 y + r_i2 z)) + t_i
      q[i] = _mm_add_ps(_mm_add_ps(_mm_mul_ps(row(rotation_soa_[static_cast<std::size_t>(3 * i)]), px),
                                   _mm_add_ps(_mm_mul_ps(row(rotation_soa_[static_cast<std::size_t>(3 * i + 1)]), py),
                                              _mm_mul_ps(row(rotation_soa_[static_cast<std::size_t>(3 * i + 2)]), pz))),
                        row(offset_soa_[static_cast<std::size_t>(i)]));
    __m128i lo[3], hi[3];
    __m128 f[3];
    for (int i = 0; i < 3; ++i) {
      // detail::floorInt, then detail::fade(x - float(ix)).
      __m128i ix = _mm_cvttps_epi32(q[i]);
      ix = _mm_add_epi32(ix, _mm_castps_si128(_mm_cmplt_ps(q[i], _mm_cvtepi32_ps(ix))));  // -1 where x < int(x)
      const __m128 x = _mm_sub_ps(q[i], _mm_cvtepi32_ps(ix));
      const __m128 a = _mm_mul_ps(_mm_mul_ps(x, x), x);
      const __m128 b = _mm_add_ps(_mm_mul_ps(x, _mm_sub_ps(_mm_mul_ps(x, _mm_set1_ps(6.0f)), _mm_set1_ps(15.0f))),
                                  _mm_set1_ps(10.0f));
      f[i] = _mm_mul_ps(a, b);
      lo[i] = _mm_and_si128(ix, m);
      hi[i] = _mm_and_si128(_mm_add_epi32(ix, one), m);
    }
    // Row (y · kSize) and slice (z · kSize²) offsets.
    lo[1] = _mm_slli_epi32(lo[1], 6);
    hi[1] = _mm_slli_epi32(hi[1], 6);
    lo[2] = _mm_slli_epi32(lo[2], 12);
    hi[2] = _mm_slli_epi32(hi[2], 12);
    static_assert(kSize == 64, "the shifts above assume a 64-cell lattice");
    alignas(16) std::int32_t x0[4], x1[4], y0[4], y1[4], z0[4], z1[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(x0), lo[0]);
    _mm_store_si128(reinterpret_cast<__m128i*>(x1), hi[0]);
    _mm_store_si128(reinterpret_cast<__m128i*>(y0), lo[1]);
    _mm_store_si128(reinterpret_cast<__m128i*>(y1), hi[1]);
    _mm_store_si128(reinterpret_cast<__m128i*>(z0), lo[2]);
    _mm_store_si128(reinterpret_cast<__m128i*>(z1), hi[2]);
    const auto at = [&](const std::int32_t* z, const std::int32_t* y, const std::int32_t* x) {
      return _mm_cvtepi32_ps(_mm_setr_epi32(t[z[0] + y[0] + x[0]], t[z[1] + y[1] + x[1]], t[z[2] + y[2] + x[2]],
                                            t[z[3] + y[3] + x[3]]));
    };
    const auto lerp = [](__m128 a, __m128 b, __m128 s) { return _mm_add_ps(a, _mm_mul_ps(s, _mm_sub_ps(b, a))); };
    const __m128 a00 = lerp(at(z0, y0, x0), at(z0, y0, x1), f[0]);
    const __m128 a10 = lerp(at(z0, y1, x0), at(z0, y1, x1), f[0]);
    const __m128 a01 = lerp(at(z1, y0, x0), at(z1, y0, x1), f[0]);
    const __m128 a11 = lerp(at(z1, y1, x0), at(z1, y1, x1), f[0]);
    const __m128 r = _mm_mul_ps(lerp(lerp(a00, a10, f[1]), lerp(a01, a11, f[1]), f[2]), _mm_set1_ps(1.0f / 127.0f));
    if (count >= 4) {
      _mm_storeu_ps(out, r);
    } else {
      alignas(16) float tail[4];
      _mm_store_ps(tail, r);
      for (int k = 0; k < count; ++k) out[k] = tail[k];
    }
  }
#else
  for (int k = 0; k < count; ++k) out[k] = octave(p, first + k);
#endif
}

#if defined(EVIO_VALUE_NOISE_AVX2)
namespace {
/// The lattice values at x and x + 1 (mod kSize) of the row at offset zy of
/// the paired table (ValueLattice::pairs_): the first two of the 4 bytes read
/// at zy + x, sign-extended.
struct ValuePair {
  __m256 lo, hi;
};
EVIO_AVX2_INLINE ValuePair gatherPair(const int* pairs, __m256i zy, __m256i x) {
  const __m256i g = _mm256_i32gather_epi32(pairs, _mm256_add_epi32(zy, x), 1);
  return {_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(g, 24), 24)),
          _mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_slli_epi32(g, 16), 24))};
}

/// Offsets of row y (y · 65) and of slice z (z · 65 · 64) in the paired table.
EVIO_AVX2_INLINE __m256i pairedRow(__m256i y) { return _mm256_add_epi32(_mm256_slli_epi32(y, 6), y); }
EVIO_AVX2_INLINE __m256i pairedSlice(__m256i z) {
  return _mm256_add_epi32(_mm256_slli_epi32(z, 12), _mm256_slli_epi32(z, 6));
}

/// ValueLattice::value at eight points q (lattice units), lane by lane the
/// float operations of value() in its order (detail::floorInt, detail::fade,
/// seven interpolations, × 1/127), the values read from the paired table:
/// four gathers of two neighbours along x each.
EVIO_AVX2_INLINE __m256 latticeValue8(const __m256 (&q)[3], const int* pairs) {
  const __m256i m = _mm256_set1_epi32(ValueLattice::kSize - 1), one = _mm256_set1_epi32(1);
  __m256i lo[3], hi[3];
  __m256 f[3];
  for (int i = 0; i < 3; ++i) {
    __m256i ix = _mm256_cvttps_epi32(q[i]);
    ix = _mm256_add_epi32(ix, _mm256_castps_si256(_mm256_cmp_ps(q[i], _mm256_cvtepi32_ps(ix), _CMP_LT_OQ)));
    const __m256 x = _mm256_sub_ps(q[i], _mm256_cvtepi32_ps(ix));
    const __m256 a = _mm256_mul_ps(_mm256_mul_ps(x, x), x);
    const __m256 b = _mm256_add_ps(
        _mm256_mul_ps(x, _mm256_sub_ps(_mm256_mul_ps(x, _mm256_set1_ps(6.0f)), _mm256_set1_ps(15.0f))),
        _mm256_set1_ps(10.0f));
    f[i] = _mm256_mul_ps(a, b);
    lo[i] = _mm256_and_si256(ix, m);
    hi[i] = _mm256_and_si256(_mm256_add_epi32(ix, one), m);
  }
  static_assert(ValueLattice::kSize == 64, "the shifts below assume a 64-cell lattice");
  const __m256i y0 = pairedRow(lo[1]), y1 = pairedRow(hi[1]), z0 = pairedSlice(lo[2]), z1 = pairedSlice(hi[2]);
  using scenes::avx2::lerp;
  const ValuePair p00 = gatherPair(pairs, _mm256_add_epi32(z0, y0), lo[0]);
  const ValuePair p10 = gatherPair(pairs, _mm256_add_epi32(z0, y1), lo[0]);
  const ValuePair p01 = gatherPair(pairs, _mm256_add_epi32(z1, y0), lo[0]);
  const ValuePair p11 = gatherPair(pairs, _mm256_add_epi32(z1, y1), lo[0]);
  const __m256 a00 = lerp(p00.lo, p00.hi, f[0]);
  const __m256 a10 = lerp(p10.lo, p10.hi, f[0]);
  const __m256 a01 = lerp(p01.lo, p01.hi, f[0]);
  const __m256 a11 = lerp(p11.lo, p11.hi, f[0]);
  return _mm256_mul_ps(lerp(lerp(a00, a10, f[1]), lerp(a01, a11, f[1]), f[2]), _mm256_set1_ps(1.0f / 127.0f));
}
}  // namespace

// octaveValues with eight octaves side by side (AVX2, no FMA: the same float
// operations in the same order as octave()).
EVIO_AVX2 void ValueLattice::octaveValues8(const Eigen::Vector3f& p, int first, int count, float* out) const {
  const __m256 px = _mm256_set1_ps(p.x()), py = _mm256_set1_ps(p.y()), pz = _mm256_set1_ps(p.z());
  const auto k = static_cast<std::size_t>(first);
  __m256 q[3];
  for (std::size_t i = 0; i < 3; ++i)  // (r_i0 x + (r_i1 y + r_i2 z)) + t_i, as in octaveValues
    q[i] = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&rotation_soa_[3 * i][k]), px),
                                       _mm256_add_ps(_mm256_mul_ps(_mm256_loadu_ps(&rotation_soa_[3 * i + 1][k]), py),
                                                     _mm256_mul_ps(_mm256_loadu_ps(&rotation_soa_[3 * i + 2][k]), pz))),
                         _mm256_loadu_ps(&offset_soa_[i][k]));
  alignas(32) float all[8];
  _mm256_store_ps(all, latticeValue8(q, reinterpret_cast<const int*>(pairs_.data())));
  for (int j = 0; j < count; ++j) out[j] = all[j];
}

EVIO_AVX2 void ValueLattice::value8Avx2(const float* x, const float* y, const float* z, float* out) const {
  const __m256 q[3] = {_mm256_loadu_ps(x), _mm256_loadu_ps(y), _mm256_loadu_ps(z)};
  _mm256_storeu_ps(out, latticeValue8(q, reinterpret_cast<const int*>(pairs_.data())));
}

EVIO_AVX2 void ValueLattice::fbm8Avx2(const float* x, const float* y, const float* z, int octaves, float gain,
                                      const float* footprint, float* out) const {
  // fbm() lane by lane: the same norm, level-of-detail weights and sum order.
  if (octaves > kMaxOctaves) octaves = kMaxOctaves;
  float norm = 0.0f;
  {
    float a = 1.0f;
    for (int o = 0; o < octaves; ++o, a *= gain) norm += a;
  }
  const __m256 px = _mm256_loadu_ps(x), py = _mm256_loadu_ps(y), pz = _mm256_loadu_ps(z);
  const __m256 fp = _mm256_loadu_ps(footprint);
  const __m256 four = _mm256_set1_ps(4.0f), eight = _mm256_set1_ps(8.0f), half = _mm256_set1_ps(0.5f);
  __m256 ratio = _mm256_blendv_ps(_mm256_set1_ps(1e30f), _mm256_div_ps(_mm256_set1_ps(1.0f), fp),
                                  _mm256_cmp_ps(fp, _mm256_setzero_ps(), _CMP_GT_OQ));
  __m256 active = _mm256_castsi256_ps(_mm256_set1_epi32(-1));
  __m256 sum = _mm256_setzero_ps();
  const auto* base = reinterpret_cast<const int*>(pairs_.data());
  float amp = 1.0f;
  for (int o = 0; o < octaves; ++o, ratio = _mm256_mul_ps(ratio, half), amp *= gain) {
    active = _mm256_and_ps(active, _mm256_cmp_ps(ratio, four, _CMP_NLE_UQ));  // fbm stops at ratio <= 4
    if (_mm256_movemask_ps(active) == 0) break;
    const __m256 weight = _mm256_blendv_ps(_mm256_set1_ps(1.0f), _mm256_mul_ps(_mm256_sub_ps(ratio, four), _mm256_set1_ps(0.25f)),
                                           _mm256_cmp_ps(ratio, eight, _CMP_LT_OQ));
    const __m256 scale = _mm256_mul_ps(weight, _mm256_set1_ps(amp));
    const auto k = static_cast<std::size_t>(o);
    __m256 q[3];
    for (std::size_t i = 0; i < 3; ++i)  // (r_i0 x + (r_i1 y + r_i2 z)) + t_i, as in octaveValues
      q[i] = _mm256_add_ps(
          _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(rotation_soa_[3 * i][k]), px),
                        _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(rotation_soa_[3 * i + 1][k]), py),
                                      _mm256_mul_ps(_mm256_set1_ps(rotation_soa_[3 * i + 2][k]), pz))),
          _mm256_set1_ps(offset_soa_[i][k]));
    const __m256 v = latticeValue8(q, base);
    sum = _mm256_blendv_ps(sum, _mm256_add_ps(sum, _mm256_mul_ps(scale, v)), active);
  }
  _mm256_storeu_ps(out, _mm256_div_ps(sum, _mm256_set1_ps(norm)));
}
#else
void ValueLattice::value8Avx2(const float* x, const float* y, const float* z, float* out) const {
  for (int k = 0; k < 8; ++k) out[k] = value(Eigen::Vector3f(x[k], y[k], z[k]));
}
void ValueLattice::fbm8Avx2(const float* x, const float* y, const float* z, int octaves, float gain,
                            const float* footprint, float* out) const {
  for (int k = 0; k < 8; ++k) out[k] = fbm(Eigen::Vector3f(x[k], y[k], z[k]), octaves, gain, footprint[k]);
}
#endif

float ValueLattice::fbm(const Eigen::Vector3f& p, int octaves, float gain, float footprint) const {
  if (octaves > kMaxOctaves) octaves = kMaxOctaves;
  float norm = 0.0f;
  {
    float a = 1.0f;
    for (int o = 0; o < octaves; ++o, a *= gain) norm += a;
  }
  // ratio = wavelength / footprint = 1 / (2^o footprint).
  float ratio = footprint > 0.0f ? 1.0f / footprint : 1e30f;
  float scale[kMaxOctaves];  // weight_o · gain^o of the octaves kept
  int count = 0;
  float amp = 1.0f;
  for (int o = 0; o < octaves; ++o, ratio *= 0.5f, amp *= gain) {
    if (ratio <= 4.0f) break;
    const float weight = ratio < 8.0f ? (ratio - 4.0f) * 0.25f : 1.0f;
    scale[o] = weight * amp;
    count = o + 1;
  }
  // Groups of three or four octaves side by side; one or two alone (a group
  // costs about as much as two single octaves).
  float values[kMaxOctaves];
  int o = 0;
#if defined(EVIO_VALUE_NOISE_AVX2)
  if (avx2_)
    for (; count - o >= 5; o += 8) octaveValues8(p, o, std::min(8, count - o), values + o);
#endif
  for (; count - o >= 3; o += 4) octaveValues(p, o, std::min(4, count - o), values + o);
  for (; o < count; ++o) values[o] = octave(p, o);
  float sum = 0.0f;
  for (int k = 0; k < count; ++k) sum += scale[k] * values[k];
  return sum / norm;
}

}  // namespace evio::noise

#pragma once
// Private to the scenes module: the AVX2 helpers of the 8-lane texture
// lookups (mip_map.cpp, value_noise.cpp, texture.cpp). Every helper does the
// float operations of its scalar counterpart, lane by lane, in the same
// order and without FMA, so that the lanes are bit-identical to the scalar
// code (tests: MipMap.EightLaneSampleMatchesTheScalarOneBitForBit and
// the texture and noise tests of the same name).

#if defined(__GNUC__) && defined(__x86_64__)
#define EVIO_SCENES_AVX2 1
#include <immintrin.h>

#define EVIO_AVX2 __attribute__((target("avx2")))
#define EVIO_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline
#define EVIO_AVX2_LAMBDA __attribute__((target("avx2"), always_inline))  // after a lambda's parameter list

namespace evio::scenes::avx2 {

/// x < 0 ? 0 : (x > 1 ? 1 : x), NaN kept (as the scalar clamp01).
EVIO_AVX2_INLINE __m256 clamp01(__m256 x) {
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  const __m256 hi = _mm256_blendv_ps(x, one, _mm256_cmp_ps(x, one, _CMP_GT_OQ));
  return _mm256_blendv_ps(hi, zero, _mm256_cmp_ps(x, zero, _CMP_LT_OQ));
}

/// a + s (b − a).
EVIO_AVX2_INLINE __m256 lerp(__m256 a, __m256 b, __m256 s) {
  return _mm256_add_ps(a, _mm256_mul_ps(s, _mm256_sub_ps(b, a)));
}

}  // namespace evio::scenes::avx2
#endif

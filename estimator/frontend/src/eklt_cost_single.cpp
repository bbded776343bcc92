// The EKLT cost's sums with the Jacobian in single precision, sixteen patch
// pixels per group (eklt_sums.h sumPatchSingle).
//
// The arithmetic is written once with GCC vector types of sixteen floats
// and compiled three times: for AVX-512F (one 512-bit register per vector),
// for AVX (two 256-bit registers) and for the x86-64 baseline (four SSE
// registers). Either way every lane
// sees the same IEEE single-precision operations in the same order (the
// build forbids FMA contraction), so all three paths give the same bits. Only the
// gathering of the template taps, which moves floats without arithmetic,
// differs: 8×8 transposes with AVX and AVX-512, a plain copy otherwise.
//
// Per pixel u this is pixelTerm of eklt_cost.cpp: the warped point in crop
// coordinates x = R u + (t − origin), the Catmull-Rom weights of its
// fractional part, the template gradient g and ∂g/∂x from the 4×4 taps,
// a = −g·w and ∂a/∂p. The patch is one flat run of P² pixels, sixteen
// consecutive pixels per group whatever the row length. Each group's lanes accumulate their own partial sums
// (Σ a², Σ a m, Σ|a|, the ten products of D, Σ a ∂a/∂p, Σ m ∂a/∂p), added
// lane by lane in double precision at the end.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "eklt_sums.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define EVIO_EKLT_SINGLE_AVX 1
#endif

#define EVIO_LANES inline __attribute__((always_inline))

// Vector types of 64 bytes without AVX-512 change the calling convention of
// functions taking them by value; every such function here is inlined.
#pragma GCC diagnostic ignored "-Wpsabi"

namespace evio::estimator::detail {

namespace baseline_lanes {
#include "eklt_cost_single_lanes.inc"
}  // namespace baseline_lanes

#if defined(EVIO_EKLT_SINGLE_AVX)
#pragma GCC push_options
#pragma GCC target("avx")
#define EVIO_LANES_AVX 1
namespace avx_lanes {
#include "eklt_cost_single_lanes.inc"
}  // namespace avx_lanes
#pragma GCC pop_options
#pragma GCC push_options
#pragma GCC target("avx512f")
namespace avx512_lanes {
#include "eklt_cost_single_lanes.inc"
}  // namespace avx512_lanes
#pragma GCC pop_options
#undef EVIO_LANES_AVX
#endif

void sumPatchSingle(const EkltBatch& batch, const EkltWarp& warp, SimdLevel level, EkltSums* sums) {
#if defined(EVIO_EKLT_SINGLE_AVX)
  if (level == SimdLevel::kAvx512) {
    avx512_lanes::sumPatchLanes(batch, warp, sums);
    return;
  }
  if (level == SimdLevel::kAvx) {
    avx_lanes::sumPatchLanes(batch, warp, sums);
    return;
  }
#endif
  (void)level;
  baseline_lanes::sumPatchLanes(batch, warp, sums);
}

}  // namespace evio::estimator::detail

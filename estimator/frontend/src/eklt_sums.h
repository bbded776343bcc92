#pragma once
// Internal to the EKLT cost (eklt_cost.cpp, eklt_cost_single.cpp): the sums
// over the patch that evaluateEklt turns into cost, JᵀJ and Jᵀr.
#include "evio/estimator/frontend/eklt_cost.h"

namespace evio::estimator::detail {

struct EkltSums {
  double aa = 0.0, am = 0.0, abs_sum = 0.0;  // Σ a², Σ a m, Σ |a|
  double d[4][4] = {};                       // D = Σ ∂a/∂pᵀ ∂a/∂p (upper triangle used)
  Vec4 da_a = Vec4::Zero();                  // Σ a ∂a/∂p
  Vec4 da_m = Vec4::Zero();                  // Σ m ∂a/∂p
};

/// One parameter vector's warp W(u) = R(θ) u + t and flow w = R(θ) v(φ)
/// (eklt_cost.h), w⊥ = ∂w/∂φ.
struct EkltWarp {
  double c, s;  // cos θ, sin θ
  Vec2 t;
  Vec2 w, w_perp;
};

/// The instruction set of the single-precision lanes (the caller checked
/// the CPU has it).
enum class SimdLevel { kBaseline, kAvx, kAvx512 };

/// The sums with the Jacobian in single precision, sixteen pixels per lane
/// group, lane-wise partial sums added in a fixed order at the end. Needs
/// P ≥ 4 (P² ≥ 16) and every lookup's 4×4 taps inside the template crop.
/// Every lane operation is one IEEE single-precision operation, without FMA,
/// in the same order on the AVX-512, AVX and SSE2 paths: the same bits on
/// any x86-64 CPU.
void sumPatchSingle(const EkltBatch& batch, const EkltWarp& warp, SimdLevel level, EkltSums* sums);

#if defined(__GNUC__) && defined(__x86_64__)
/// The sums with the Jacobian in double precision, four pixels per AVX
/// register (eklt_cost_double_avx.cpp), the same bits as the one-pixel loop
/// of eklt_cost.cpp. `inside`: every lookup's taps inside the crop (else the
/// template's clamped lookup). Needs P ≥ 4 and a CPU with AVX.
void sumPatchDoubleAvx(const EkltBatch& batch, const EkltWarp& warp, bool inside, EkltSums* sums);
#endif


}  // namespace evio::estimator::detail

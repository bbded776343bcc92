// The EKLT cost's sums in double precision, four patch pixels per AVX
// register (eklt_sums.h sumPatchDoubleAvx): for a warp inside the crop with
// the Jacobian when single precision is off, and for warps reaching outside
// it. Every lane does the double operations of the one-pixel path
// (eklt_cost.cpp pixelTerm) in the same order, without FMA, so each pixel's
// a(u) and ∂a/∂p are the same bits; the sums then take the pixels one by one
// in row-major order, as the one-pixel loop does (each sum's rounding
// depends on that order), with the ten products of D, and a·∂a/∂p, m·∂a/∂p,
// as 4-lane vectors of one pixel.
#include <algorithm>
#include <cstddef>

#include "eklt_sums.h"

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>

namespace evio::estimator::detail {

namespace {

#define EVIO_AVX __attribute__((target("avx"), always_inline)) inline

EVIO_AVX __m256d avxNeg(__m256d x) { return _mm256_xor_pd(x, _mm256_set1_pd(-0.0)); }

/// catmullRomWeights, one fractional position per lane.
EVIO_AVX void catmullRomWeights4(__m256d t, __m256d w[4], __m256d dw[4]) {
  const __m256d half = _mm256_set1_pd(0.5);
#define k(v) _mm256_set1_pd(v)
  const __m256d t2 = _mm256_mul_pd(t, t);
  const __m256d t3 = _mm256_mul_pd(t2, t);
  w[0] = _mm256_mul_pd(half, _mm256_sub_pd(_mm256_add_pd(avxNeg(t3), _mm256_mul_pd(k(2.0), t2)), t));
  w[1] = _mm256_mul_pd(half, _mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(k(3.0), t3), _mm256_mul_pd(k(5.0), t2)), k(2.0)));
  w[2] = _mm256_mul_pd(half, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(k(-3.0), t3), _mm256_mul_pd(k(4.0), t2)), t));
  w[3] = _mm256_mul_pd(half, _mm256_sub_pd(t3, t2));
  dw[0] = _mm256_mul_pd(half, _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(k(-3.0), t2), _mm256_mul_pd(k(4.0), t)), k(1.0)));
  dw[1] = _mm256_mul_pd(half, _mm256_sub_pd(_mm256_mul_pd(k(9.0), t2), _mm256_mul_pd(k(10.0), t)));
  dw[2] = _mm256_mul_pd(half, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(k(-9.0), t2), _mm256_mul_pd(k(8.0), t)), k(1.0)));
  dw[3] = _mm256_mul_pd(half, _mm256_sub_pd(_mm256_mul_pd(k(3.0), t2), _mm256_mul_pd(k(2.0), t)));
#undef k
}

/// One pixel into the sums: a, m and G = ∂a/∂p (also as the array g).
EVIO_AVX void accumulatePixel(double a, double m, __m256d G, const double* g, EkltSums& s, __m256d D[4],
                              __m256d& da_a, __m256d& da_m) {
  s.aa += a * a;
  s.am += a * m;
  s.abs_sum += std::abs(a);
  for (int r = 0; r < 4; ++r) D[r] = _mm256_add_pd(D[r], _mm256_mul_pd(_mm256_set1_pd(g[r]), G));
  da_a = _mm256_add_pd(da_a, _mm256_mul_pd(_mm256_set1_pd(a), G));
  da_m = _mm256_add_pd(da_m, _mm256_mul_pd(_mm256_set1_pd(m), G));
}

/// Value and derivatives of the template gradient at four points (a lane
/// each), per channel (gx, gy): f, ∂f/∂x (column), ∂f/∂y (row).
struct Samples4 {
  __m256d f[2], fdx[2], fdy[2];
};

/// Row i of the 4×4 taps of four lanes, given each lane's pointer to its 8
/// floats (4 taps of (gx, gy)), as one register per (tap, channel), a lane
/// per point: taps[j][k].
EVIO_AVX void transposeTapRow(const float* const row[4], __m256d taps[4][2]) {
  __m128 lo[4], hi[4];
  for (int l = 0; l < 4; ++l) {
    const __m256 v = _mm256_loadu_ps(row[l]);
    lo[l] = _mm256_castps256_ps128(v);
    hi[l] = _mm256_extractf128_ps(v, 1);
  }
  _MM_TRANSPOSE4_PS(lo[0], lo[1], lo[2], lo[3]);  // gx0, gy0, gx1, gy1
  _MM_TRANSPOSE4_PS(hi[0], hi[1], hi[2], hi[3]);  // gx2, gy2, gx3, gy3
  const __m128 t[8] = {lo[0], lo[1], lo[2], lo[3], hi[0], hi[1], hi[2], hi[3]};
  for (int j = 0; j < 4; ++j)
    for (int k = 0; k < 2; ++k) taps[j][k] = _mm256_cvtps_pd(t[2 * j + k]);
}

/// sampleInside (Catmull-Rom weights) at crop coordinates (cx, cy), lane by
/// lane; every lane's taps inside the crop.
EVIO_AVX Samples4 sampleCatmullRom4(const GradientTemplate& templ, __m256d cx, __m256d cy) {
  const __m256d fx = _mm256_floor_pd(cx), fy = _mm256_floor_pd(cy);
  __m256d wx[4], dwx[4], wy[4], dwy[4];
  catmullRomWeights4(_mm256_sub_pd(cx, fx), wx, dwx);
  catmullRomWeights4(_mm256_sub_pd(cy, fy), wy, dwy);
  alignas(16) int ix[4], iy[4];
  _mm_store_si128(reinterpret_cast<__m128i*>(ix), _mm256_cvttpd_epi32(fx));
  _mm_store_si128(reinterpret_cast<__m128i*>(iy), _mm256_cvttpd_epi32(fy));
  const int n = templ.size();
  const float* base[4];
  for (int l = 0; l < 4; ++l) base[l] = templ.data() + 2 * ((iy[l] - 1) * n + ix[l] - 1);
  const __m256d zero = _mm256_setzero_pd();
  Samples4 out{{zero, zero}, {zero, zero}, {zero, zero}};
  for (int i = 0; i < 4; ++i) {
    const float* row[4];
    for (int l = 0; l < 4; ++l) row[l] = base[l] + 2 * i * n;
    __m256d taps[4][2];
    transposeTapRow(row, taps);
    for (int k = 0; k < 2; ++k) {
      __m256d r = zero, d = zero;
      for (int j = 0; j < 4; ++j) {
        r = _mm256_add_pd(r, _mm256_mul_pd(wx[j], taps[j][k]));
        d = _mm256_add_pd(d, _mm256_mul_pd(dwx[j], taps[j][k]));
      }
      out.f[k] = _mm256_add_pd(out.f[k], _mm256_mul_pd(wy[i], r));
      out.fdx[k] = _mm256_add_pd(out.fdx[k], _mm256_mul_pd(wy[i], d));
      out.fdy[k] = _mm256_add_pd(out.fdy[k], _mm256_mul_pd(dwy[i], r));
    }
  }
  return out;
}

/// The cubic Hermite step of GradientTemplate::sample (its `hermite`), lane
/// by lane: value f and derivative df in t.
EVIO_AVX void hermite4(__m256d p0, __m256d p1, __m256d p2, __m256d p3, __m256d t, __m256d* f, __m256d* df) {
  const __m256d half = _mm256_set1_pd(0.5);
#define k(v) _mm256_set1_pd(v)
  const __m256d a = _mm256_mul_pd(
      half, _mm256_add_pd(_mm256_sub_pd(_mm256_add_pd(avxNeg(p0), _mm256_mul_pd(k(3.0), p1)), _mm256_mul_pd(k(3.0), p2)),
                          p3));
  const __m256d b = _mm256_mul_pd(
      half, _mm256_sub_pd(_mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(k(2.0), p0), _mm256_mul_pd(k(5.0), p1)),
                                        _mm256_mul_pd(k(4.0), p2)),
                          p3));
  const __m256d c = _mm256_mul_pd(half, _mm256_add_pd(avxNeg(p0), p2));
  *f = _mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(a, t), b), t), c), t), p1);
  if (df != nullptr)
    *df = _mm256_add_pd(
        _mm256_mul_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_mul_pd(k(3.0), a), t), _mm256_mul_pd(k(2.0), b)), t), c);
#undef k
}

/// GradientTemplate::sample at crop coordinates (cx, cy), lane by lane: the
/// taps clamped to the crop, Hermite along the columns of each tap row, then
/// along the rows (the same index arithmetic, in scalar code per lane).
EVIO_AVX Samples4 sampleHermite4(const GradientTemplate& templ, __m256d cx, __m256d cy) {
  const __m256d fc = _mm256_floor_pd(cx), fr = _mm256_floor_pd(cy);
  const __m256d tc = _mm256_sub_pd(cx, fc), tr = _mm256_sub_pd(cy, fr);
  alignas(32) double fcl[4], frl[4];
  _mm256_store_pd(fcl, fc);
  _mm256_store_pd(frl, fr);
  const int n = templ.size();
  const auto clampIndex = [n](int i) { return std::clamp(i, 0, n - 1); };
  int col[4], row[4];
  for (int l = 0; l < 4; ++l) {
    col[l] = static_cast<int>(fcl[l]);
    row[l] = static_cast<int>(frl[l]);
  }
  alignas(32) float scratch[4][8];  // a lane's clamped taps when its columns leave the crop
  __m256d rows_f[4][2], rows_dfdc[4][2];
  for (int i = 0; i < 4; ++i) {
    const float* ptr[4];
    for (int l = 0; l < 4; ++l) {
      const float* base = templ.data() + static_cast<std::size_t>(clampIndex(row[l] - 1 + i)) * static_cast<std::size_t>(n) * 2;
      if (col[l] - 1 >= 0 && col[l] + 2 <= n - 1) {
        ptr[l] = base + 2 * (col[l] - 1);
        continue;
      }
      for (int j = 0; j < 4; ++j) {
        const float* v = base + 2 * clampIndex(col[l] - 1 + j);
        scratch[l][2 * j] = v[0];
        scratch[l][2 * j + 1] = v[1];
      }
      ptr[l] = scratch[l];
    }
    __m256d taps[4][2];
    transposeTapRow(ptr, taps);
    for (int k = 0; k < 2; ++k)
      hermite4(taps[0][k], taps[1][k], taps[2][k], taps[3][k], tc, &rows_f[i][k], &rows_dfdc[i][k]);
  }
  Samples4 out;
  for (int k = 0; k < 2; ++k) {
    hermite4(rows_f[0][k], rows_f[1][k], rows_f[2][k], rows_f[3][k], tr, &out.f[k], &out.fdy[k]);
    hermite4(rows_dfdc[0][k], rows_dfdc[1][k], rows_dfdc[2][k], rows_dfdc[3][k], tr, &out.fdx[k], nullptr);
  }
  return out;
}

/// a(u) and ∂a/∂p of four pixels u = (ux[l], uy): pixelTerm lane by lane,
/// through sampleInside (`inside`) or GradientTemplate::sample.
struct Terms4 {
  __m256d a, da[4];
};

__attribute__((target("avx"))) Terms4 pixelTerms4(const GradientTemplate& templ, const EkltWarp& warp, __m256d ux,
                                                  __m256d uy, bool inside) {
  const __m256d C = _mm256_set1_pd(warp.c), S = _mm256_set1_pd(warp.s);
  const __m256d Wx =
      _mm256_add_pd(_mm256_sub_pd(_mm256_mul_pd(C, ux), _mm256_mul_pd(S, uy)), _mm256_set1_pd(warp.t.x()));
  const __m256d Wy =
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(S, ux), _mm256_mul_pd(C, uy)), _mm256_set1_pd(warp.t.y()));
  const __m256d cx = _mm256_sub_pd(Wx, _mm256_set1_pd(static_cast<double>(templ.originX())));
  const __m256d cy = _mm256_sub_pd(Wy, _mm256_set1_pd(static_cast<double>(templ.originY())));
  const Samples4 smp = inside ? sampleCatmullRom4(templ, cx, cy) : sampleHermite4(templ, cx, cy);
  const __m256d* f = smp.f;
  const __m256d* fdx = smp.fdx;
  const __m256d* fdy = smp.fdy;
  // pixelTerm: a = −g·w, b = −(∂g/∂W)ᵀ w, ∂a/∂p.
  const __m256d w0 = _mm256_set1_pd(warp.w.x()), w1 = _mm256_set1_pd(warp.w.y());
  const __m256d wp0 = _mm256_set1_pd(warp.w_perp.x()), wp1 = _mm256_set1_pd(warp.w_perp.y());
  Terms4 t;
  t.a = avxNeg(_mm256_add_pd(_mm256_mul_pd(f[0], w0), _mm256_mul_pd(f[1], w1)));
  const __m256d b0 = avxNeg(_mm256_add_pd(_mm256_mul_pd(fdx[0], w0), _mm256_mul_pd(fdx[1], w1)));
  const __m256d b1 = avxNeg(_mm256_add_pd(_mm256_mul_pd(fdy[0], w0), _mm256_mul_pd(fdy[1], w1)));
  const __m256d dW0 = _mm256_sub_pd(_mm256_mul_pd(avxNeg(S), ux), _mm256_mul_pd(C, uy));
  const __m256d dW1 = _mm256_sub_pd(_mm256_mul_pd(C, ux), _mm256_mul_pd(S, uy));
  const __m256d g_wp = _mm256_add_pd(_mm256_mul_pd(f[0], wp0), _mm256_mul_pd(f[1], wp1));
  t.da[0] = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(b0, dW0), _mm256_mul_pd(b1, dW1)), g_wp);
  t.da[1] = b0;
  t.da[2] = b1;
  t.da[3] = avxNeg(g_wp);
  return t;
}

}  // namespace

__attribute__((target("avx"))) void sumPatchDoubleAvx(const EkltBatch& batch, const EkltWarp& frame, bool inside,
                                                      EkltSums* sums) {
  const int P = batch.patch_size;
  const double h = 0.5 * (P - 1);
  const __m256d zero = _mm256_setzero_pd();
  __m256d D[4] = {zero, zero, zero, zero};
  __m256d da_a = zero, da_m = zero;
  EkltSums& s = *sums;
  for (int i = 0; i < P; ++i) {
    const double uy = i - h;
    const float* m_row = batch.measured + static_cast<std::ptrdiff_t>(i) * P;
    // Groups of four columns; the last group is aligned to the row's end and
    // overlaps the one before (P ≥ 4 and P not a multiple of 4): its lanes
    // already summed are skipped, so every pixel is summed once, in order.
    for (int j = 0; j < P; j += 4) {
      const int j0 = std::min(j, P - 4);
      const __m256d ux = _mm256_setr_pd(j0 - h, (j0 + 1) - h, (j0 + 2) - h, (j0 + 3) - h);
      const Terms4 t = pixelTerms4(*batch.templ, frame, ux, _mm256_set1_pd(uy), inside);
      // Lanes to pixels: a, m and the 4×4 transpose of ∂a/∂p.
      alignas(32) double a[4], g[4][4];
      _mm256_store_pd(a, t.a);
      const __m256d t0 = _mm256_unpacklo_pd(t.da[0], t.da[1]), t1 = _mm256_unpackhi_pd(t.da[0], t.da[1]);
      const __m256d t2 = _mm256_unpacklo_pd(t.da[2], t.da[3]), t3 = _mm256_unpackhi_pd(t.da[2], t.da[3]);
      const __m256d G[4] = {_mm256_permute2f128_pd(t0, t2, 0x20), _mm256_permute2f128_pd(t1, t3, 0x20),
                            _mm256_permute2f128_pd(t0, t2, 0x31), _mm256_permute2f128_pd(t1, t3, 0x31)};
      for (int l = 0; l < 4; ++l) _mm256_store_pd(g[l], G[l]);
      for (int l = j - j0; l < 4; ++l)
        accumulatePixel(a[l], static_cast<double>(m_row[j0 + l]), G[l], g[l], s, D, da_a, da_m);
    }
  }
  for (int r = 0; r < 4; ++r) _mm256_storeu_pd(s.d[r], D[r]);
  _mm256_storeu_pd(s.da_a.data(), da_a);
  _mm256_storeu_pd(s.da_m.data(), da_m);
}

#undef EVIO_AVX
}  // namespace evio::estimator::detail

#endif

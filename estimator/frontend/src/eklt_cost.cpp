#include "evio/estimator/frontend/eklt_cost.h"

#include "evio/core/cpu_features.h"
#include "eklt_sums.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#if defined(__GNUC__) && defined(__x86_64__)
#include <immintrin.h>
#define EVIO_EKLT_AVX 1  // an AVX path for the bicubic lookup, chosen at run time
#endif

namespace evio::estimator {

namespace {

/// Per-pixel predicted increment a(u) and ∂a/∂p.
struct PixelTerm {
  double a;
  Vec4 da;
};

/// Shared geometry of one parameter vector.
struct WarpFrame {
  double c, s;          // cos θ, sin θ
  Vec2 w;               // R v
  Vec2 w_perp;          // R v⊥ = ∂(R v)/∂φ
  Vec2 t;

  explicit WarpFrame(const Vec4& p) : c(std::cos(p[0])), s(std::sin(p[0])), t(p[1], p[2]) {
    const double cv = std::cos(p[3]);
    const double sv = std::sin(p[3]);
    w = Vec2(c * cv - s * sv, s * cv + c * sv);
    w_perp = Vec2(-w.y(), w.x());
  }
};

/// Catmull-Rom weights of the 4 taps at fractional position t ∈ [0, 1) and
/// their derivatives in t: the same cubic Hermite polynomial as
/// GradientTemplate::sample and ceres::BiCubicInterpolator, written as weights.
inline void catmullRomWeights(double t, double w[4], double dw[4]) {
  const double t2 = t * t;
  const double t3 = t2 * t;
  w[0] = 0.5 * (-t3 + 2.0 * t2 - t);
  w[1] = 0.5 * (3.0 * t3 - 5.0 * t2 + 2.0);
  w[2] = 0.5 * (-3.0 * t3 + 4.0 * t2 + t);
  w[3] = 0.5 * (t3 - t2);
  dw[0] = 0.5 * (-3.0 * t2 + 4.0 * t - 1.0);
  dw[1] = 0.5 * (9.0 * t2 - 10.0 * t);
  dw[2] = 0.5 * (-9.0 * t2 + 8.0 * t + 1.0);
  dw[3] = 0.5 * (3.0 * t2 - 2.0 * t);
}

/// Bicubic sample of the interleaved template with derivatives, for points
/// whose 4×4 taps lie inside the crop (checked by the caller).
/// The 4×4 taps of a bicubic lookup at template point W: Catmull-Rom weights
/// (and their derivatives) along x and y, and the interleaved (gx, gy) of the
/// top-left tap; rows are 2·n floats apart.
struct BicubicTaps {
  double wx[4], dwx[4], wy[4], dwy[4];
  const float* base;
  int n;
};

inline BicubicTaps bicubicTaps(const GradientTemplate& templ, const Vec2& W) {
  BicubicTaps t;
  const double cx = W.x() - templ.originX();
  const double cy = W.y() - templ.originY();
  const double fx = std::floor(cx);
  const double fy = std::floor(cy);
  catmullRomWeights(cx - fx, t.wx, t.dwx);
  catmullRomWeights(cy - fy, t.wy, t.dwy);
  t.n = templ.size();
  t.base = templ.data() + 2 * ((static_cast<int>(fy) - 1) * t.n + static_cast<int>(fx) - 1);
  return t;
}

inline void sampleInside(const GradientTemplate& templ, const Vec2& W, Vec2* g, Mat2* dg) {
  const BicubicTaps t = bicubicTaps(templ, W);
  const double *wx = t.wx, *dwx = t.dwx, *wy = t.wy, *dwy = t.dwy;
  const float* base = t.base;
  const int n = t.n;
  // Both channels (gx, gy) at once as 2-vectors: value, ∂/∂x, ∂/∂y.
  using A2 = Eigen::Array2d;
  A2 f = A2::Zero(), fdx = A2::Zero(), fdy = A2::Zero();
  for (int i = 0; i < 4; ++i) {
    const float* row = base + 2 * i * n;
    A2 r = A2::Zero(), d = A2::Zero();
    for (int j = 0; j < 4; ++j) {
      const A2 v(static_cast<double>(row[2 * j]), static_cast<double>(row[2 * j + 1]));
      r += wx[j] * v;
      d += dwx[j] * v;
    }
    f += wy[i] * r;
    fdx += wy[i] * d;
    fdy += dwy[i] * r;
  }
  *g = Vec2(f[0], f[1]);
  if (dg != nullptr) *dg << fdx[0], fdy[0], fdx[1], fdy[1];
}

#if defined(EVIO_EKLT_AVX)
/// sampleInside with two template rows per 256-bit register (rows i and
/// i + 1 side by side, each as its (gx, gy) pair): every lane sees the same
/// double operations in the same order as sampleInside (products, then sums
/// over the taps j, then over the rows i from 0 to 3; AVX without FMA), so
/// the result is bit-identical to it.
__attribute__((target("avx"))) void sampleInsideAvx(const GradientTemplate& templ, const Vec2& W, Vec2* g,
                                                    Mat2* dg) {
  const BicubicTaps t = bicubicTaps(templ, W);
  const double *wx = t.wx, *dwx = t.dwx, *wy = t.wy, *dwy = t.dwy;
  const float* base = t.base;
  const int n = t.n;
  __m128d f = _mm_setzero_pd(), fdx = _mm_setzero_pd(), fdy = _mm_setzero_pd();
  for (int pair = 0; pair < 2; ++pair) {
    const float* row_a = base + 2 * (2 * pair) * n;
    const float* row_b = row_a + 2 * n;
    __m256d r = _mm256_setzero_pd(), d = _mm256_setzero_pd();
    for (int j = 0; j < 4; ++j) {
      // (gx, gy) of tap j on both rows, as doubles: [a.gx, a.gy, b.gx, b.gy].
      const __m128 v4 = _mm_loadh_pi(_mm_loadl_pi(_mm_setzero_ps(), reinterpret_cast<const __m64*>(row_a + 2 * j)),
                                     reinterpret_cast<const __m64*>(row_b + 2 * j));
      const __m256d v = _mm256_cvtps_pd(v4);
      r = _mm256_add_pd(r, _mm256_mul_pd(_mm256_set1_pd(wx[j]), v));
      d = _mm256_add_pd(d, _mm256_mul_pd(_mm256_set1_pd(dwx[j]), v));
    }
    const int i = 2 * pair;
    const __m256d w = _mm256_setr_pd(wy[i], wy[i], wy[i + 1], wy[i + 1]);
    const __m256d dw = _mm256_setr_pd(dwy[i], dwy[i], dwy[i + 1], dwy[i + 1]);
    const __m256d pf = _mm256_mul_pd(w, r), pdx = _mm256_mul_pd(w, d), pdy = _mm256_mul_pd(dw, r);
    // Row i, then row i + 1, as the scalar loop adds them.
    f = _mm_add_pd(_mm_add_pd(f, _mm256_castpd256_pd128(pf)), _mm256_extractf128_pd(pf, 1));
    fdx = _mm_add_pd(_mm_add_pd(fdx, _mm256_castpd256_pd128(pdx)), _mm256_extractf128_pd(pdx, 1));
    fdy = _mm_add_pd(_mm_add_pd(fdy, _mm256_castpd256_pd128(pdy)), _mm256_extractf128_pd(pdy, 1));
  }
  alignas(16) double fv[2], fdxv[2], fdyv[2];
  _mm_store_pd(fv, f);
  _mm_store_pd(fdxv, fdx);
  _mm_store_pd(fdyv, fdy);
  *g = Vec2(fv[0], fv[1]);
  if (dg != nullptr) *dg << fdxv[0], fdyv[0], fdxv[1], fdyv[1];
}

#endif

/// sampleInside, through the AVX path when the CPU has it (the same bits).
inline void sampleInsideFast(const GradientTemplate& templ, const Vec2& W, Vec2* g, Mat2* dg, bool avx) {
#if defined(EVIO_EKLT_AVX)
  if (avx) {
    sampleInsideAvx(templ, W, g, dg);
    return;
  }
#endif
  (void)avx;
  sampleInside(templ, W, g, dg);
}

inline PixelTerm pixelTerm(const GradientTemplate& templ, const WarpFrame& f, double ux, double uy,
                           bool with_jacobian, bool inside, bool avx = false) {
  // W = R u + t;   ∂W/∂θ = R' u = (−s ux − c uy, c ux − s uy).
  const Vec2 W(f.c * ux - f.s * uy + f.t.x(), f.s * ux + f.c * uy + f.t.y());
  Vec2 g;
  Mat2 dg;
  if (inside)
    sampleInsideFast(templ, W, &g, with_jacobian ? &dg : nullptr, avx);
  else
    templ.sample(W, &g, with_jacobian ? &dg : nullptr);
  PixelTerm term{};
  term.a = -g.dot(f.w);
  if (!with_jacobian) return term;
  // ∂a/∂W = −wᵀ ∂g/∂W.
  const Vec2 b = -(dg.transpose() * f.w);
  const Vec2 dW_dtheta(-f.s * ux - f.c * uy, f.c * ux - f.s * uy);
  // ∂(R v)/∂θ = R' v = (R v)⊥ (a 90° turn), the same vector as ∂(R v)/∂φ.
  term.da[0] = b.dot(dW_dtheta) - g.dot(f.w_perp);
  term.da[1] = b.x();
  term.da[2] = b.y();
  term.da[3] = -g.dot(f.w_perp);
  return term;
}

/// True when every warped patch pixel has its 4×4 bicubic taps inside the
/// crop: the patch corners at distance h√2 from the centre t bound them.
inline bool warpInside(const GradientTemplate& templ, const WarpFrame& f, int P) {
  const double r = 0.5 * (P - 1) * std::sqrt(2.0) + 2.0;
  const double lo = 1.0;
  const double hi = templ.size() - 3.0;
  const double cx = f.t.x() - templ.originX();
  const double cy = f.t.y() - templ.originY();
  return cx - r >= lo && cy - r >= lo && cx + r < hi && cy + r < hi;
}

using detail::EkltSums;

#if defined(EVIO_EKLT_AVX)
// evaluateEklt for a warp inside the crop, with the Jacobian, four patch
// pixels (columns j … j+3 of a row) per 256-bit register. Every lane does the
// double operations of the one-pixel path (pixelTerm with sampleInside) in
// the same order, without FMA, so each pixel's a(u) and ∂a/∂p are the same
// bits; the sums then take the pixels one by one in row-major order, as the
// one-pixel loop does (each sum's rounding depends on that order), with the
// ten products of D, and a·∂a/∂p, m·∂a/∂p, as 4-lane vectors of one pixel.

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

__attribute__((target("avx"))) Terms4 pixelTerms4(const GradientTemplate& templ, const WarpFrame& warp, __m256d ux,
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

__attribute__((target("avx"))) void sumPatchAvx(const EkltBatch& batch, const WarpFrame& frame, bool inside,
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
#endif

}  // namespace

namespace detail {
bool ekltSampleHasAvx() { return cpuHasAvx(); }
void ekltSampleInside(const GradientTemplate& templ, const Vec2& W, Vec2* g, Mat2* dg, bool avx) {
  sampleInsideFast(templ, W, g, dg, avx && cpuHasAvx());
}
}  // namespace detail

namespace {

/// The one-pixel loop over the patch (any warp; with or without the Jacobian).
void sumPatch(const EkltBatch& batch, const WarpFrame& frame, bool with_jacobian, bool inside, bool avx,
              EkltSums* sums) {
  const int P = batch.patch_size;
  const double h = 0.5 * (P - 1);
  double aa = 0.0, am = 0.0, abs_sum = 0.0;
  // Upper triangle of D = Σ ∂a/∂pᵀ ∂a/∂p, accumulated by hand (10 terms).
  double d00 = 0, d01 = 0, d02 = 0, d03 = 0, d11 = 0, d12 = 0, d13 = 0, d22 = 0, d23 = 0, d33 = 0;
  Vec4 da_a = Vec4::Zero();
  Vec4 da_m = Vec4::Zero();
  for (int i = 0; i < P; ++i) {
    const double uy = i - h;
    const float* m_row = batch.measured + static_cast<std::ptrdiff_t>(i) * P;
    for (int j = 0; j < P; ++j) {
      const PixelTerm t = pixelTerm(*batch.templ, frame, j - h, uy, with_jacobian, inside, avx);
      const double m = static_cast<double>(m_row[j]);
      aa += t.a * t.a;
      am += t.a * m;
      abs_sum += std::abs(t.a);
      if (with_jacobian) {
        const double g0 = t.da[0], g1 = t.da[1], g2 = t.da[2], g3 = t.da[3];
        d00 += g0 * g0;
        d01 += g0 * g1;
        d02 += g0 * g2;
        d03 += g0 * g3;
        d11 += g1 * g1;
        d12 += g1 * g2;
        d13 += g1 * g3;
        d22 += g2 * g2;
        d23 += g2 * g3;
        d33 += g3 * g3;
        da_a += t.a * t.da;
        da_m += m * t.da;
      }
    }
  }
  EkltSums& s = *sums;
  s.aa = aa;
  s.am = am;
  s.abs_sum = abs_sum;
  const double upper[4][4] = {{d00, d01, d02, d03}, {0, d11, d12, d13}, {0, 0, d22, d23}, {0, 0, 0, d33}};
  for (int r = 0; r < 4; ++r)
    for (int c = r; c < 4; ++c) s.d[r][c] = upper[r][c];
  s.da_a = da_a;
  s.da_m = da_m;
}

}  // namespace

namespace {

/// The instruction set for the single-precision lanes: the highest the CPU
/// has, at most `limit` (0 baseline, 1 AVX, 2 AVX-512F).
detail::SimdLevel simdLevel(int limit) {
  if (limit >= 2 && cpuHasAvx512f()) return detail::SimdLevel::kAvx512;
  if (limit >= 1 && cpuHasAvx()) return detail::SimdLevel::kAvx;
  return detail::SimdLevel::kBaseline;
}

/// `simd`: the single-precision lanes' instruction set; the double-precision
/// paths take AVX whenever it is not the baseline.
bool evaluateWith(const EkltBatch& batch, const Vec4& p, bool with_jacobian, detail::SimdLevel simd,
                  EkltEvaluation* out) {
  const bool avx = simd != detail::SimdLevel::kBaseline;
  const WarpFrame frame(p);
  const bool inside = warpInside(*batch.templ, frame, batch.patch_size);
  EkltSums s;
  if (batch.single_precision && with_jacobian && inside && batch.patch_size >= 4)
    detail::sumPatchSingle(batch, detail::EkltWarp{frame.c, frame.s, frame.t, frame.w, frame.w_perp}, simd, &s);
#if defined(EVIO_EKLT_AVX)
  else if (avx && with_jacobian && batch.patch_size >= 4)
    sumPatchAvx(batch, frame, inside, &s);
#endif
  else
    sumPatch(batch, frame, with_jacobian, inside, avx, &s);
  const double aa = s.aa;
  if (!(aa > 0.0) || !std::isfinite(aa)) return false;
  const double n = std::sqrt(aa);
  out->rho = s.am / n;
  out->cost = 1.0 - out->rho;  // ½(‖â‖² − 2âᵀm + ‖m‖²) with unit norms
  out->abs_sum = s.abs_sum;
  if (with_jacobian) {
    Mat4 Dfull;
    Dfull << s.d[0][0], s.d[0][1], s.d[0][2], s.d[0][3],  //
        s.d[0][1], s.d[1][1], s.d[1][2], s.d[1][3],        //
        s.d[0][2], s.d[1][2], s.d[2][2], s.d[2][3],        //
        s.d[0][3], s.d[1][3], s.d[2][3], s.d[3][3];
    const Vec4 sv = s.da_a / n;
    out->jtj = (Dfull - sv * sv.transpose()) / aa;
    out->jtr = (out->rho * sv - s.da_m) / n;
  }
  return true;
}

}  // namespace

bool evaluateEklt(const EkltBatch& batch, const Vec4& p, bool with_jacobian, EkltEvaluation* out) {
  static const detail::SimdLevel best = simdLevel(2);
  return evaluateWith(batch, p, with_jacobian, best, out);
}

namespace detail {
bool evaluateEkltPath(const EkltBatch& batch, const Vec4& p, int simd_limit, EkltEvaluation* out) {
  return evaluateWith(batch, p, true, simdLevel(simd_limit), out);
}
int ekltSimdLevel(int simd_limit) { return static_cast<int>(simdLevel(simd_limit)); }
}  // namespace detail

bool ekltResiduals(const EkltBatch& batch, const Vec4& p, VecX* r, MatX* d_r_d_p) {
  const int P = batch.patch_size;
  const int N = P * P;
  const double h = 0.5 * (P - 1);
  const WarpFrame frame(p);
  VecX a(N);
  MatX da(N, 4);
  for (int i = 0; i < P; ++i)
    for (int j = 0; j < P; ++j) {
      const PixelTerm t = pixelTerm(*batch.templ, frame, j - h, i - h, d_r_d_p != nullptr, false);
      a[i * P + j] = t.a;
      if (d_r_d_p != nullptr) da.row(i * P + j) = t.da.transpose();
    }
  const double n = a.norm();
  if (!(n > 0.0)) return false;
  const VecX a_hat = a / n;
  r->resize(N);
  for (int k = 0; k < N; ++k) (*r)[k] = a_hat[k] - static_cast<double>(batch.measured[k]);
  if (d_r_d_p != nullptr) {
    // ∂â/∂p = (I − â âᵀ) ∂a/∂p / n.
    const Eigen::RowVector4d s = a_hat.transpose() * da;
    *d_r_d_p = (da - a_hat * s) / n;
  }
  return true;
}

Vec2 ekltFeaturePosition(const Vec4& p, const Vec2& accumulation_centre, const Vec2& x0) {
  const double c = std::cos(p[0]);
  const double s = std::sin(p[0]);
  const Vec2 d = x0 - Vec2(p[1], p[2]);
  return accumulation_centre + Vec2(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
}

Mat2 ekltPositionCovariance(const EkltEvaluation& eval, const Vec4& p, const Vec2& x0, int patch_size,
                            double sigma_min_px, double sigma_max_px) {
  const double dof = static_cast<double>(patch_size) * patch_size - 4.0;
  // A perfect fit (cost 0) would claim zero noise: the floor σ_min takes over below.
  const double sigma_r2 = std::max(2.0 * eval.cost / dof, 1e-300);
  Mat4 info = eval.jtj / sigma_r2;
  const double prior_angle = 1.0 / (M_PI * M_PI);
  const double prior_t = 1.0 / (sigma_max_px * sigma_max_px);
  info.diagonal() += Vec4(prior_angle, prior_t, prior_t, prior_angle);
  const Mat4 cov_p = info.ldlt().solve(Mat4::Identity());
  // c = c_acc + R(θ)ᵀ d, d = x0 − t:  ∂c/∂θ = (∂Rᵀ/∂θ) d,  ∂c/∂t = −Rᵀ.
  const double c = std::cos(p[0]);
  const double s = std::sin(p[0]);
  const Vec2 d = x0 - Vec2(p[1], p[2]);
  Eigen::Matrix<double, 2, 4> G = Eigen::Matrix<double, 2, 4>::Zero();
  G.col(0) = Vec2(-s * d.x() + c * d.y(), -c * d.x() - s * d.y());
  G.block<2, 2>(0, 1) << -c, -s, s, -c;
  const Mat2 cov = G * cov_p * G.transpose();
  const Eigen::SelfAdjointEigenSolver<Mat2> eig(0.5 * (cov + cov.transpose()));
  if (eig.info() != Eigen::Success || !eig.eigenvalues().allFinite())
    return Mat2::Identity() * sigma_max_px * sigma_max_px;
  const Vec2 lambda = eig.eigenvalues().cwiseMax(sigma_min_px * sigma_min_px).cwiseMin(sigma_max_px * sigma_max_px);
  return eig.eigenvectors() * lambda.asDiagonal() * eig.eigenvectors().transpose();
}

}  // namespace evio::estimator

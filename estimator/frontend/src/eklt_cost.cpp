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
    detail::sumPatchDoubleAvx(batch, detail::EkltWarp{frame.c, frame.s, frame.t, frame.w, frame.w_perp}, inside, &s);
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

double ekltSigmaFloor(double cost, double sigma_min_px, double sigma_max_px, double cost_ref) {
  if (!(cost_ref > 0.0)) return sigma_min_px;
  return std::min(sigma_min_px * std::max(1.0, cost / cost_ref), sigma_max_px);
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

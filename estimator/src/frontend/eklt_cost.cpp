#include "evio/estimator/frontend/eklt_cost.h"

#include <cmath>

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
inline void sampleInside(const GradientTemplate& templ, const Vec2& W, Vec2* g, Mat2* dg) {
  const double cx = W.x() - templ.originX();
  const double cy = W.y() - templ.originY();
  const double fx = std::floor(cx);
  const double fy = std::floor(cy);
  double wx[4], dwx[4], wy[4], dwy[4];
  catmullRomWeights(cx - fx, wx, dwx);
  catmullRomWeights(cy - fy, wy, dwy);
  const int n = templ.size();
  const float* base = templ.data() + 2 * ((static_cast<int>(fy) - 1) * n + static_cast<int>(fx) - 1);
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

inline PixelTerm pixelTerm(const GradientTemplate& templ, const WarpFrame& f, double ux, double uy,
                           bool with_jacobian, bool inside) {
  // W = R u + t;   ∂W/∂θ = R' u = (−s ux − c uy, c ux − s uy).
  const Vec2 W(f.c * ux - f.s * uy + f.t.x(), f.s * ux + f.c * uy + f.t.y());
  Vec2 g;
  Mat2 dg;
  if (inside)
    sampleInside(templ, W, &g, with_jacobian ? &dg : nullptr);
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

}  // namespace

bool evaluateEklt(const EkltBatch& batch, const Vec4& p, bool with_jacobian, EkltEvaluation* out) {
  const int P = batch.patch_size;
  const double h = 0.5 * (P - 1);
  const WarpFrame frame(p);
  const bool inside = warpInside(*batch.templ, frame, P);
  double aa = 0.0, am = 0.0, abs_sum = 0.0;
  // Upper triangle of D = Σ ∂a/∂pᵀ ∂a/∂p, accumulated by hand (10 terms).
  double d00 = 0, d01 = 0, d02 = 0, d03 = 0, d11 = 0, d12 = 0, d13 = 0, d22 = 0, d23 = 0, d33 = 0;
  Vec4 da_a = Vec4::Zero();
  Vec4 da_m = Vec4::Zero();
  for (int i = 0; i < P; ++i) {
    const double uy = i - h;
    const float* m_row = batch.measured + static_cast<std::ptrdiff_t>(i) * P;
    for (int j = 0; j < P; ++j) {
      const PixelTerm t = pixelTerm(*batch.templ, frame, j - h, uy, with_jacobian, inside);
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
  if (!(aa > 0.0) || !std::isfinite(aa)) return false;
  const double n = std::sqrt(aa);
  out->rho = am / n;
  out->cost = 1.0 - out->rho;  // ½(‖â‖² − 2âᵀm + ‖m‖²) with unit norms
  out->abs_sum = abs_sum;
  if (with_jacobian) {
    Mat4 Dfull;
    Dfull << d00, d01, d02, d03,  //
        d01, d11, d12, d13,       //
        d02, d12, d22, d23,       //
        d03, d13, d23, d33;
    const Vec4 s = da_a / n;
    out->jtj = (Dfull - s * s.transpose()) / aa;
    out->jtr = (out->rho * s - da_m) / n;
  }
  return true;
}

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

}  // namespace evio::estimator

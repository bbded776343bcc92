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
  double f0 = 0.0, f1 = 0.0, fx0 = 0.0, fx1 = 0.0, fy0 = 0.0, fy1 = 0.0;
  for (int i = 0; i < 4; ++i) {
    const float* row = base + 2 * i * n;
    double r0 = 0.0, r1 = 0.0, d0 = 0.0, d1 = 0.0;
    for (int j = 0; j < 4; ++j) {
      const double v0 = static_cast<double>(row[2 * j]);
      const double v1 = static_cast<double>(row[2 * j + 1]);
      r0 += wx[j] * v0;
      r1 += wx[j] * v1;
      d0 += dwx[j] * v0;
      d1 += dwx[j] * v1;
    }
    f0 += wy[i] * r0;
    f1 += wy[i] * r1;
    fx0 += wy[i] * d0;
    fx1 += wy[i] * d1;
    fy0 += dwy[i] * r0;
    fy1 += dwy[i] * r1;
  }
  *g = Vec2(f0, f1);
  if (dg != nullptr) *dg << fx0, fy0, fx1, fy1;
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
  Mat4 D = Mat4::Zero();
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
        D.selfadjointView<Eigen::Upper>().rankUpdate(t.da);
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
    const Mat4 Dfull = D.selfadjointView<Eigen::Upper>();
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

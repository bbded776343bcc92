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

inline PixelTerm pixelTerm(const GradientTemplate& templ, const WarpFrame& f, double ux, double uy,
                           bool with_jacobian) {
  // W = R u + t;   ∂W/∂θ = R' u = (−s ux − c uy, c ux − s uy).
  const Vec2 W(f.c * ux - f.s * uy + f.t.x(), f.s * ux + f.c * uy + f.t.y());
  Vec2 g;
  PixelTerm term{};
  if (!with_jacobian) {
    templ.sample(W, &g, nullptr);
    term.a = -g.dot(f.w);
    return term;
  }
  Mat2 dg;
  templ.sample(W, &g, &dg);
  term.a = -g.dot(f.w);
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

}  // namespace

bool evaluateEklt(const EkltBatch& batch, const Vec4& p, bool with_jacobian, EkltEvaluation* out) {
  const int P = batch.patch_size;
  const double h = 0.5 * (P - 1);
  const WarpFrame frame(p);
  double aa = 0.0, am = 0.0, abs_sum = 0.0;
  Mat4 D = Mat4::Zero();
  Vec4 da_a = Vec4::Zero();
  Vec4 da_m = Vec4::Zero();
  for (int i = 0; i < P; ++i) {
    const double uy = i - h;
    const float* m_row = batch.measured + static_cast<std::ptrdiff_t>(i) * P;
    for (int j = 0; j < P; ++j) {
      const PixelTerm t = pixelTerm(*batch.templ, frame, j - h, uy, with_jacobian);
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
      const PixelTerm t = pixelTerm(*batch.templ, frame, j - h, i - h, d_r_d_p != nullptr);
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

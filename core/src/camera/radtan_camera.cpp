#include "evio/core/camera/radtan_camera.h"

#include <algorithm>
#include <cmath>

#include "polynomial_roots.h"
#include "validate_intrinsics.h"

namespace evio {

RadTanCamera::RadTanCamera(int width, int height, const Params& params)
    : width_(width), height_(height), params_(params), r2_max_(kMaxRadiusSquared) {
  detail::validateCameraParams(width, height, params, {"k1", "k2", "p1", "p2", "k3"});
  const double k1 = params[4], k2 = params[5], k3 = params[8];
  // d(r R(r²))/dr = 1 + 3 k1 r² + 5 k2 r⁴ + 7 k3 r⁶, as a polynomial in s = r².
  r2_max_ = detail::firstNonPositive({1.0, 3.0 * k1, 5.0 * k2, 7.0 * k3}, kMaxRadiusSquared);
}

Vec2 RadTanCamera::distort(const Vec2& n, Mat2* d_nd_d_n) const {
  const double k1 = params_[4], k2 = params_[5], p1 = params_[6], p2 = params_[7], k3 = params_[8];
  const double a = n.x(), b = n.y();
  const double r2 = a * a + b * b;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const Vec2 nd(a * radial + 2.0 * p1 * a * b + p2 * (r2 + 2.0 * a * a),
                b * radial + p1 * (r2 + 2.0 * b * b) + 2.0 * p2 * a * b);
  if (d_nd_d_n) {
    const double d_radial_d_r2 = k1 + r2 * (2.0 * k2 + 3.0 * k3 * r2);
    // ∂R/∂a = 2a R', ∂R/∂b = 2b R'.
    (*d_nd_d_n)(0, 0) = radial + 2.0 * a * a * d_radial_d_r2 + 2.0 * p1 * b + 6.0 * p2 * a;
    (*d_nd_d_n)(0, 1) = 2.0 * a * b * d_radial_d_r2 + 2.0 * p1 * a + 2.0 * p2 * b;
    (*d_nd_d_n)(1, 0) = 2.0 * a * b * d_radial_d_r2 + 2.0 * p1 * a + 2.0 * p2 * b;
    (*d_nd_d_n)(1, 1) = radial + 2.0 * b * b * d_radial_d_r2 + 6.0 * p1 * b + 2.0 * p2 * a;
  }
  return nd;
}

bool RadTanCamera::isValid(const Vec2& n, const Mat2& d_nd_d_n) const {
  return n.squaredNorm() < r2_max_ && d_nd_d_n.determinant() > 0.0;
}

bool RadTanCamera::project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p,
                           ParamsJacobian* d_uv_d_params) const {
  if (!isInFrontOfCamera(p_C)) return false;
  const Vec2 n(p_C.x() / p_C.z(), p_C.y() / p_C.z());
  Mat2 d_nd_d_n;
  const Vec2 nd = distort(n, &d_nd_d_n);
  if (!isValid(n, d_nd_d_n)) return false;
  *uv = Vec2(fx() * nd.x() + cx(), fy() * nd.y() + cy());
  if (d_uv_d_p) {
    const Eigen::Matrix<double, 2, 3> d_nd_d_p = d_nd_d_n * dNormalizedDPoint(p_C);
    d_uv_d_p->row(0) = fx() * d_nd_d_p.row(0);
    d_uv_d_p->row(1) = fy() * d_nd_d_p.row(1);
  }
  if (d_uv_d_params) {
    const double a = n.x(), b = n.y();
    const double r2 = a * a + b * b, r4 = r2 * r2, r6 = r4 * r2;
    auto& J = *d_uv_d_params;
    J.setZero();
    J(0, 0) = nd.x();
    J(1, 1) = nd.y();
    J(0, 2) = 1.0;
    J(1, 3) = 1.0;
    // k1, k2, p1, p2, k3
    J(0, 4) = fx() * a * r2;
    J(1, 4) = fy() * b * r2;
    J(0, 5) = fx() * a * r4;
    J(1, 5) = fy() * b * r4;
    J(0, 6) = fx() * 2.0 * a * b;
    J(1, 6) = fy() * (r2 + 2.0 * b * b);
    J(0, 7) = fx() * (r2 + 2.0 * a * a);
    J(1, 7) = fy() * 2.0 * a * b;
    J(0, 8) = fx() * a * r6;
    J(1, 8) = fy() * b * r6;
  }
  return true;
}

bool RadTanCamera::unproject(const Vec2& uv, Vec3* bearing_C) const {
  if (!uv.allFinite()) return false;
  const Vec2 target((uv.x() - cx()) / fx(), (uv.y() - cy()) / fy());
  // Residual of distort(n) = target, in pixels.
  auto residualPx = [&](const Vec2& nd) {
    return Vec2(fx() * (nd.x() - target.x()), fy() * (nd.y() - target.y())).norm();
  };
  Vec2 n = target;
  Mat2 J;
  Vec2 nd = distort(n, &J);
  double err = residualPx(nd);
  for (int iter = 0; iter < 100 && err > kUnprojectTolerancePx; ++iter) {
    const double det = J.determinant();
    if (!(std::abs(det) > 1e-300)) return false;
    const Vec2 step = J.inverse() * (nd - target);
    // Backtracking: halve the Newton step until the residual decreases.
    double scale = 1.0;
    bool improved = false;
    for (int k = 0; k < 60; ++k, scale *= 0.5) {
      const Vec2 n_try = n - scale * step;
      Mat2 J_try;
      const Vec2 nd_try = distort(n_try, &J_try);
      const double err_try = residualPx(nd_try);
      if (n_try.allFinite() && err_try < err) {
        n = n_try;
        nd = nd_try;
        J = J_try;
        err = err_try;
        improved = true;
        break;
      }
    }
    if (!improved) break;  // at the floating-point floor of distort()
  }
  if (!(err <= kUnprojectFloorPx)) return false;
  if (!isValid(n, J)) return false;
  *bearing_C = Vec3(n.x(), n.y(), 1.0).normalized();
  return true;
}

}  // namespace evio

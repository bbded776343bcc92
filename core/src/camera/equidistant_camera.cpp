#include "evio/core/camera/equidistant_camera.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "polynomial_roots.h"
#include "validate_intrinsics.h"

namespace evio {

namespace {
// Below this r = |(a, b)| the ratio θ_d / r and its derivative use their
// Taylor expansions (error O(r⁴) < 1e-32) instead of 0/0.
constexpr double kSmallRadius = 1e-8;
}  // namespace

EquidistantCamera::EquidistantCamera(int width, int height, const Params& params)
    : width_(width), height_(height), params_(params), theta_max_(std::numbers::pi / 2.0) {
  detail::validateCameraParams(width, height, params, {"k1", "k2", "k3", "k4"});
  const double k1 = params[4], k2 = params[5], k3 = params[6], k4 = params[7];
  // dθ_d/dθ = 1 + 3 k1 θ² + 5 k2 θ⁴ + 7 k3 θ⁶ + 9 k4 θ⁸, a polynomial in s = θ².
  const double s_max = detail::firstNonPositive(
      {1.0, 3.0 * k1, 5.0 * k2, 7.0 * k3, 9.0 * k4}, theta_max_ * theta_max_);
  theta_max_ = std::min(theta_max_, std::sqrt(s_max));
}

double EquidistantCamera::distortTheta(double theta, double* d_thetad_d_theta) const {
  const double k1 = params_[4], k2 = params_[5], k3 = params_[6], k4 = params_[7];
  const double t2 = theta * theta;
  if (d_thetad_d_theta)
    *d_thetad_d_theta = 1.0 + t2 * (3.0 * k1 + t2 * (5.0 * k2 + t2 * (7.0 * k3 + t2 * 9.0 * k4)));
  return theta * (1.0 + t2 * (k1 + t2 * (k2 + t2 * (k3 + t2 * k4))));
}

bool EquidistantCamera::project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p,
                                ParamsJacobian* d_uv_d_params) const {
  if (!isInFrontOfCamera(p_C)) return false;
  const double a = p_C.x() / p_C.z();
  const double b = p_C.y() / p_C.z();
  const double r2 = a * a + b * b;
  const double r = std::sqrt(r2);
  const double theta = std::atan(r);
  if (!(theta < theta_max_)) return false;
  const double k1 = params_[4];
  double d_thetad_d_theta = 0.0;
  const double thetad = distortTheta(theta, &d_thetad_d_theta);
  // s = θ_d / r and q = (ds/dr) / r, so that ∂(s a)/∂a = s + q a², ∂(s a)/∂b = q a b.
  double s = 0.0, q = 0.0, theta_over_r = 1.0;
  if (r < kSmallRadius) {
    s = 1.0 + (k1 - 1.0 / 3.0) * r2;
    q = 2.0 * (k1 - 1.0 / 3.0);
  } else {
    s = thetad / r;
    q = (d_thetad_d_theta / (1.0 + r2) - s) / r2;  // dθ/dr = 1 / (1 + r²)
    theta_over_r = theta / r;
  }
  const double ad = s * a, bd = s * b;
  *uv = Vec2(fx() * ad + cx(), fy() * bd + cy());
  if (d_uv_d_p) {
    Mat2 d_nd_d_n;
    d_nd_d_n << s + q * a * a, q * a * b,  //
        q * a * b, s + q * b * b;
    const Mat23 d_nd_d_p = d_nd_d_n * dNormalizedDPoint(p_C);
    d_uv_d_p->row(0) = fx() * d_nd_d_p.row(0);
    d_uv_d_p->row(1) = fy() * d_nd_d_p.row(1);
  }
  if (d_uv_d_params) {
    auto& J = *d_uv_d_params;
    J.setZero();
    J(0, 0) = ad;
    J(1, 1) = bd;
    J(0, 2) = 1.0;
    J(1, 3) = 1.0;
    // ∂θ_d/∂k_i = θ^(2i+1), so ∂(s a)/∂k_i = a (θ / r) θ^(2i).
    const double t2 = theta * theta;
    double t_pow = t2;
    for (int i = 0; i < 4; ++i, t_pow *= t2) {
      J(0, 4 + i) = fx() * a * theta_over_r * t_pow;
      J(1, 4 + i) = fy() * b * theta_over_r * t_pow;
    }
  }
  return true;
}

bool EquidistantCamera::unproject(const Vec2& uv, Vec3* bearing_C) const {
  if (!uv.allFinite()) return false;
  const double mx = (uv.x() - cx()) / fx();
  const double my = (uv.y() - cy()) / fy();
  const double rho = std::hypot(mx, my);
  if (rho == 0.0) {
    *bearing_C = Vec3(0.0, 0.0, 1.0);
    return true;
  }
  // The residual θ_d(θ) - ρ moves the pixel radially by that much times
  // fx (along x) and fy (along y): its size in pixels is at most max(fx, fy)
  // times, and at least min(fx, fy) times, the residual.
  const double px_per_unit = std::max(fx(), fy());
  if (!(rho < distortTheta(theta_max_))) return false;
  // Safeguarded Newton: θ_d is increasing on [0, θ_max), keep a bracket.
  double lo = 0.0, hi = theta_max_;
  double theta = std::clamp(rho, lo, hi);  // θ_d ≈ θ for weak distortion
  double err = 0.0;
  for (int iter = 0; iter < 200; ++iter) {
    double slope = 0.0;
    const double f = distortTheta(theta, &slope) - rho;
    err = std::abs(f) * px_per_unit;
    if (err <= kUnprojectTolerancePx) break;
    if (f > 0.0)
      hi = theta;
    else
      lo = theta;
    double next = theta - f / slope;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);  // Newton left the bracket
    if (next == theta || hi - lo <= 0.0) break;
    theta = next;
  }
  if (!(err <= kUnprojectFloorPx)) return false;
  const double sin_t = std::sin(theta);
  *bearing_C = Vec3(sin_t * mx / rho, sin_t * my / rho, std::cos(theta));
  if (!isInFrontOfCamera(*bearing_C)) return false;
  return true;
}

}  // namespace evio

#pragma once
/// @file equidistant_camera.h
/// Kannala–Brandt / equidistant fisheye model, as in OpenCV's fisheye module
/// and Kalibr's "equidistant" distortion. Conventions: camera_common.h.

#include "evio/core/camera/camera_common.h"
#include "evio/core/eigen_types.h"

namespace evio {

/// Parameters [fx, fy, cx, cy, k1, k2, k3, k4]. With (a, b) = (x / z, y / z),
/// r = √(a² + b²) and θ = atan(r) the angle from the optical axis:
///   θ_d = θ (1 + k1 θ² + k2 θ⁴ + k3 θ⁶ + k4 θ⁸)
///   u = fx (θ_d / r) a + cx,   v = fy (θ_d / r) b + cy     (θ_d / r → 1 as r → 0).
///
/// Valid region: θ < θ_max, where θ_max is the first positive root of
/// dθ_d/dθ = 1 + 3 k1 θ² + 5 k2 θ⁴ + 7 k3 θ⁶ + 9 k4 θ⁸ (θ_d increasing), capped
/// at π/2 (points must be in front of the camera, camera_common.h).
class EquidistantCamera {
 public:
  static constexpr int kNumParams = 8;
  static constexpr int kNumDistortion = 4;
  static constexpr const char* kModelName = "equidistant";
  using Params = Eigen::Matrix<double, kNumParams, 1>;
  using ParamsJacobian = Eigen::Matrix<double, 2, kNumParams>;

  /// Throws evio::Error naming the field unless width, height > 0, fx, fy > 0
  /// and all parameters are finite.
  EquidistantCamera(int width, int height, const Params& params);

  int width() const { return width_; }
  int height() const { return height_; }
  const Params& params() const { return params_; }
  double fx() const { return params_[0]; }
  double fy() const { return params_[1]; }
  double cx() const { return params_[2]; }
  double cy() const { return params_[3]; }
  /// [k1, k2, k3, k4]
  Eigen::Matrix<double, kNumDistortion, 1> distortion() const { return params_.tail<4>(); }

  /// θ_max in rad (see class comment).
  double maxTheta() const { return theta_max_; }

  /// Projects p_C to *uv (non-null). Jacobians: ∂uv/∂p_C (2×3) and
  /// ∂uv/∂[fx fy cx cy k1 k2 k3 k4] (2×8). False (outputs unspecified) behind
  /// the camera or for θ ≥ θ_max.
  bool project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p = nullptr,
               ParamsJacobian* d_uv_d_params = nullptr) const;

  /// Unit-norm bearing of pixel uv: with (m_x, m_y) = ((u-cx)/fx, (v-cy)/fy) and
  /// ρ = |m|, solves θ_d(θ) = ρ on [0, θ_max) by safeguarded Newton to a residual
  /// below kUnprojectTolerancePx pixels, then bearing = (sin θ m/ρ, cos θ).
  /// False if ρ is beyond θ_d(θ_max) or the solution is not in front of the camera.
  bool unproject(const Vec2& uv, Vec3* bearing_C) const;

  /// θ_d(θ) and optionally dθ_d/dθ.
  double distortTheta(double theta, double* d_thetad_d_theta = nullptr) const;

  friend bool operator==(const EquidistantCamera& l, const EquidistantCamera& r) {
    return l.width_ == r.width_ && l.height_ == r.height_ && l.params_ == r.params_;
  }

 private:
  int width_;
  int height_;
  Params params_;
  double theta_max_;
};

}  // namespace evio

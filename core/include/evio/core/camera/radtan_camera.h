#pragma once
/// @file radtan_camera.h
/// Pinhole camera with radial-tangential (Brown–Conrady) distortion, the
/// OpenCV convention used by calib.txt of the Event-Camera Dataset.
/// Conventions: camera_common.h.

#include "evio/core/camera/camera_common.h"
#include "evio/core/eigen_types.h"

namespace evio {

/// Parameters [fx, fy, cx, cy, k1, k2, p1, p2, k3] (the calib.txt order).
/// With (a, b) = (x / z, y / z), r² = a² + b², R = 1 + k1 r² + k2 r⁴ + k3 r⁶:
///   a_d = a R + 2 p1 a b + p2 (r² + 2 a²)
///   b_d = b R + p1 (r² + 2 b²) + 2 p2 a b
///   u = fx a_d + cx,   v = fy b_d + cy.
///
/// Valid region: the radial map r ↦ r R(r²) must be increasing, i.e.
/// 1 + 3 k1 r² + 5 k2 r⁴ + 7 k3 r⁶ > 0 for all radii up to r (the first root
/// of that polynomial is computed once, at construction, and r² is also capped
/// at kMaxRadiusSquared), and the 2×2 Jacobian of the distortion must have a
/// positive determinant. Outside it project() and unproject() return false.
class RadTanCamera {
 public:
  static constexpr int kNumParams = 9;
  static constexpr int kNumDistortion = 5;
  static constexpr const char* kModelName = "radtan";
  using Params = Eigen::Matrix<double, kNumParams, 1>;
  using ParamsJacobian = Eigen::Matrix<double, 2, kNumParams>;

  /// r² = a² + b² is never accepted beyond this (≈ 89.94° off axis).
  static constexpr double kMaxRadiusSquared = 1e6;

  /// Throws evio::Error naming the field unless width, height > 0, fx, fy > 0
  /// and all parameters are finite.
  RadTanCamera(int width, int height, const Params& params);

  int width() const { return width_; }
  int height() const { return height_; }
  const Params& params() const { return params_; }
  double fx() const { return params_[0]; }
  double fy() const { return params_[1]; }
  double cx() const { return params_[2]; }
  double cy() const { return params_[3]; }
  /// [k1, k2, p1, p2, k3]
  Eigen::Matrix<double, kNumDistortion, 1> distortion() const { return params_.tail<5>(); }

  /// Largest r² = a² + b² of the valid region (see class comment).
  double maxRadiusSquared() const { return r2_max_; }

  /// Projects p_C to *uv (non-null). Jacobians: ∂uv/∂p_C (2×3) and
  /// ∂uv/∂[fx fy cx cy k1 k2 p1 p2 k3] (2×9). False (outputs unspecified)
  /// behind the camera or outside the valid region.
  bool project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p = nullptr,
               ParamsJacobian* d_uv_d_params = nullptr) const;

  /// Unit-norm bearing of pixel uv. Solves distort(a, b) = ((u-cx)/fx, (v-cy)/fy)
  /// by Newton's method with backtracking, starting from the distorted point,
  /// to a residual below kUnprojectTolerancePx pixels (or the floating-point
  /// floor, see kUnprojectFloorPx). False if it does not converge or the
  /// solution lies outside the valid region.
  bool unproject(const Vec2& uv, Vec3* bearing_C) const;

  /// The distortion of normalized coordinates n = (a, b) and, optionally,
  /// its 2×2 Jacobian ∂(a_d, b_d)/∂(a, b).
  Vec2 distort(const Vec2& n, Mat2* d_nd_d_n = nullptr) const;

  friend bool operator==(const RadTanCamera& l, const RadTanCamera& r) {
    return l.width_ == r.width_ && l.height_ == r.height_ && l.params_ == r.params_;
  }

 private:
  bool isValid(const Vec2& n, const Mat2& d_nd_d_n) const;

  int width_;
  int height_;
  Params params_;
  double r2_max_;
};

}  // namespace evio

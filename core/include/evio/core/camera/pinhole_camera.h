#pragma once
/// @file pinhole_camera.h
/// The ideal pinhole camera (no distortion). Conventions: camera_common.h.

#include "evio/core/camera/camera_common.h"
#include "evio/core/eigen_types.h"

namespace evio {

/// Pinhole projection with parameters [fx, fy, cx, cy] (pixels):
///   u = fx · x / z + cx,   v = fy · y / z + cy.
class PinholeCamera {
 public:
  static constexpr int kNumParams = 4;
  static constexpr const char* kModelName = "pinhole";
  using Params = Eigen::Matrix<double, kNumParams, 1>;
  using ParamsJacobian = Eigen::Matrix<double, 2, kNumParams>;

  /// Throws evio::Error naming the field ("resolution.width", "intrinsics.fx",
  /// ...) unless width, height > 0, fx, fy > 0 and all parameters are finite.
  PinholeCamera(int width, int height, const Params& params);

  int width() const { return width_; }
  int height() const { return height_; }
  const Params& params() const { return params_; }
  double fx() const { return params_[0]; }
  double fy() const { return params_[1]; }
  double cx() const { return params_[2]; }
  double cy() const { return params_[3]; }

  /// Projects p_C (camera frame, any unit) to the pixel *uv (must be non-null).
  /// Optional Jacobians: d_uv_d_p = ∂uv/∂p_C (2×3), d_uv_d_params = ∂uv/∂[fx fy cx cy].
  /// Returns false (outputs unspecified) unless isInFrontOfCamera(p_C).
  bool project(const Vec3& p_C, Vec2* uv, Mat23* d_uv_d_p = nullptr,
               ParamsJacobian* d_uv_d_params = nullptr) const;

  /// Unit-norm bearing in C of the ray through pixel uv (closed form:
  /// normalize([(u - cx) / fx, (v - cy) / fy, 1])). False for non-finite uv.
  bool unproject(const Vec2& uv, Vec3* bearing_C) const;

  friend bool operator==(const PinholeCamera& l, const PinholeCamera& r) {
    return l.width_ == r.width_ && l.height_ == r.height_ && l.params_ == r.params_;
  }

 private:
  int width_;
  int height_;
  Params params_;
};

}  // namespace evio

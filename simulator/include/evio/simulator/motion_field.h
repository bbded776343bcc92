#pragma once
/// @file motion_field.h
/// The motion field (optical flow) of a static scene seen by a moving camera,
/// computed analytically from depth and the camera's velocity.
///
/// The camera's velocity is expressed in its own frame C: with the pose
/// T_W_C(t) = (R_W_C, p_W_C),
///   ṗ_W_C = R_W_C · v_C,     Ṙ_W_C = R_W_C · [ω_C]×.
/// A static world point p_W seen at p_C = R_W_Cᵀ (p_W − p_W_C) then moves as
///   ṗ_C = −v_C − ω_C × p_C,
/// and its pixel uv = π(p_C) (the camera model, distortion included) as
///   u̇v = ∂π/∂p_C · ṗ_C      (px/s).
/// For a point at infinity (a ray that leaves the scene) only the rotation
/// remains: u̇v = ∂π/∂p_C(b) · (−ω_C × b) for its unit bearing b (∂π/∂p is
/// homogeneous of degree −1, so any point on the ray gives the same value).

#include <opencv2/core/mat.hpp>

#include "evio/core/camera/camera.h"
#include "evio/core/eigen_types.h"

namespace evio::simulator {

/// Linear and angular velocity of the camera in its own frame C.
struct CameraVelocity {
  Vec3 v_C = Vec3::Zero();      ///< m/s
  Vec3 omega_C = Vec3::Zero();  ///< rad/s
};

/// u̇v (px/s) of the static point p_C (camera frame, m). False (uv_dot
/// unspecified) when p_C does not project.
bool pointFlow(const Camera& camera, const Vec3& p_C, const CameraVelocity& velocity, Vec2* uv_dot);

/// u̇v (px/s) of a direction at infinity with unit bearing b_C.
bool directionFlow(const Camera& camera, const Vec3& b_C, const CameraVelocity& velocity, Vec2* uv_dot);

/// pointFlow and directionFlow of a pinhole camera, with the same float
/// operations in the same order (so the same bits) but without the model
/// dispatch, the pixel and the matrices the general functions compute: the
/// renderer's flow of every pixel at every render.
class PinholeFlow {
 public:
  explicit PinholeFlow(const PinholeCamera& camera) : fx_(camera.fx()), fy_(camera.fy()) {}

  double fx() const { return fx_; }
  double fy() const { return fy_; }

  /// pointFlow(camera, p_C, velocity, uv_dot).
  bool point(const Vec3& p_C, const CameraVelocity& velocity, Vec2* uv_dot) const {
    if (!isInFrontOfCamera(p_C)) return false;
    const Vec3 p_dot = -velocity.v_C - velocity.omega_C.cross(p_C);
    return apply(p_C, p_dot, uv_dot);
  }

  /// directionFlow(camera, b_C, velocity, uv_dot).
  bool direction(const Vec3& b_C, const CameraVelocity& velocity, Vec2* uv_dot) const {
    if (!isInFrontOfCamera(b_C)) return false;
    const Vec3 p_dot = -velocity.omega_C.cross(b_C);
    return apply(b_C, p_dot, uv_dot);
  }

 private:
  /// uv_dot = ∂π/∂p(p) · p_dot as PinholeCamera::project's Jacobian
  /// (rows fx · ∂n/∂p and fy · ∂n/∂p of dNormalizedDPoint) times p_dot with
  /// Eigen's association for a 2×3 by 3 product: (J₀ p₀ + J₁ p₁) + J₂ p₂.
  bool apply(const Vec3& p, const Vec3& p_dot, Vec2* uv_dot) const {
    const double z_inv = 1.0 / p.z();
    const double a = p.x() * z_inv, b = p.y() * z_inv;
    const double u0 = fx_ * z_inv, u1 = fx_ * 0.0, u2 = fx_ * (-a * z_inv);
    const double v0 = fy_ * 0.0, v1 = fy_ * z_inv, v2 = fy_ * (-b * z_inv);
    *uv_dot = Vec2((u0 * p_dot.x() + u1 * p_dot.y()) + u2 * p_dot.z(), (v0 * p_dot.x() + v1 * p_dot.y()) + v2 * p_dot.z());
    return uv_dot->allFinite();
  }

  double fx_, fy_;  ///< focal lengths (px)
};

/// The motion field of a depth image (CV_32FC1, z in C in metres; +inf for
/// rays that leave the scene; NaN for pixels without a ray): CV_32FC2 of
/// (u̇, v̇) in px/s, NaN where undefined. Pixel (x, y) is unprojected at
/// uv = (x, y) (pixel centres, camera_common.h) and p_C = b · depth / b_z.
cv::Mat motionFieldFromDepth(const Camera& camera, const cv::Mat& depth, const CameraVelocity& velocity);

}  // namespace evio::simulator

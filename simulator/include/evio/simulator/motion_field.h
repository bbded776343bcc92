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

/// The motion field of a depth image (CV_32FC1, z in C in metres; +inf for
/// rays that leave the scene; NaN for pixels without a ray): CV_32FC2 of
/// (u̇, v̇) in px/s, NaN where undefined. Pixel (x, y) is unprojected at
/// uv = (x, y) (pixel centres, camera_common.h) and p_C = b · depth / b_z.
cv::Mat motionFieldFromDepth(const Camera& camera, const cv::Mat& depth, const CameraVelocity& velocity);

}  // namespace evio::simulator

#pragma once
/// @file camera_common.h
/// Conventions shared by all camera models (pinhole_camera.h, radtan_camera.h,
/// equidistant_camera.h, camera.h).
///
/// Frames and pixels: the camera frame C has x right, y down, z forward
/// (optical axis). A pixel coordinate uv = (u, v) has u to the right and v
/// down, in pixels, with (0, 0) the *centre* of the top-left pixel; the image
/// area of a width × height camera is [-0.5, width - 0.5) × [-0.5, height - 0.5).
/// Every model first maps a point to normalized image coordinates
/// (a, b) = (x / z, y / z), then distorts them, then applies the affine map
/// u = fx · a_d + cx, v = fy · b_d + cy.

#include <cmath>

#include "evio/core/eigen_types.h"

namespace evio {

/// A point p_C is projectable only if z > kMinCosAngle · |p_C|, i.e. its ray
/// makes an angle of more than asin(1e-6) ≈ 1e-6 rad with the image plane, on
/// the front side. Points behind the camera, on the image plane or at the
/// origin are rejected.
inline constexpr double kMinCosAngle = 1e-6;

/// True when p_C is finite and strictly in front of the camera (see kMinCosAngle).
inline bool isInFrontOfCamera(const Vec3& p_C) {
  return p_C.allFinite() && p_C.z() > kMinCosAngle * p_C.norm();
}

/// Target accuracy of the iterative undistortion in unproject(): the residual
/// of the distortion equation, expressed in pixels, is driven below this.
inline constexpr double kUnprojectTolerancePx = 1e-12;

/// Unproject() accepts a solution whose residual could not be driven below
/// kUnprojectTolerancePx only because the distortion polynomial itself cannot
/// be evaluated more accurately in double precision (a few ulp of the
/// normalized coordinate times the focal length); beyond this it fails.
inline constexpr double kUnprojectFloorPx = 1e-10;

/// d(a, b)/d(p_C) for (a, b) = (x / z, y / z):
///   [1/z, 0, -x/z²; 0, 1/z, -y/z²].
inline Mat23 dNormalizedDPoint(const Vec3& p_C) {
  const double z_inv = 1.0 / p_C.z();
  const double a = p_C.x() * z_inv;
  const double b = p_C.y() * z_inv;
  Mat23 d;
  d << z_inv, 0.0, -a * z_inv,  //
      0.0, z_inv, -b * z_inv;
  return d;
}

}  // namespace evio

#pragma once
/// @file validate_intrinsics.h
/// (private to core/src/camera) Checks shared by the camera constructors.

#include <cmath>
#include <initializer_list>
#include <string>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"

namespace evio::detail {

/// Throws evio::Error naming the field unless width, height > 0,
/// fx = p[0] > 0, fy = p[1] > 0 and p[0..3] and the distortion entries
/// p[4], p[5], ... (named by `distortion_names`: k1, k2, ...) are finite.
template <class Params>
void validateCameraParams(int width, int height, const Params& p,
                          std::initializer_list<const char*> distortion_names) {
  requireField(width > 0, "resolution.width", "must be > 0 (got " + std::to_string(width) + ")");
  requireField(height > 0, "resolution.height", "must be > 0 (got " + std::to_string(height) + ")");
  requirePositive("intrinsics.fx", p[0]);
  requirePositive("intrinsics.fy", p[1]);
  requireField(std::isfinite(p[2]), "intrinsics.cx", "must be finite");
  requireField(std::isfinite(p[3]), "intrinsics.cy", "must be finite");
  Eigen::Index i = 4;
  for (const char* name : distortion_names) {
    const std::string field =
        "distortion[" + std::to_string(i - 4) + "] (" + std::string(name) + ")";
    requireField(std::isfinite(p[i]), field, "must be finite");
    ++i;
  }
}

}  // namespace evio::detail

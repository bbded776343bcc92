#pragma once
/// @file gradient_template.h
/// The EKLT template: a square crop of the log-image gradient (∂L/∂x, ∂L/∂y)
/// of the frame where a feature was initialised, stored interleaved, with
/// bicubic sampling (Catmull-Rom, i.e. cubic Hermite with central-difference
/// tangents, exactly the scheme of ceres::BiCubicInterpolator, with the same
/// clamping at the crop border) and its derivatives.

#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/eigen_types.h"

namespace evio::estimator {

class GradientTemplate {
 public:
  /// An empty template; call assign().
  GradientTemplate() = default;

  /// Copies the crop of (gx, gy) (CV_32FC1, same size) of half-width
  /// `radius_px` around the pixel nearest to `centre` (image coordinates);
  /// pixels outside the image repeat the border. Reuses its storage.
  void assign(const cv::Mat& gx, const cv::Mat& gy, const Vec2& centre, int radius_px);

  /// Gradient g = (∂L/∂x, ∂L/∂y) at image point x (bicubic) and, when
  /// d_g_d_x is given, its 2×2 derivative ∂g/∂x (rows: g components;
  /// columns: x, y).
  void sample(const Vec2& x, Vec2* g, Mat2* d_g_d_x = nullptr) const;

  /// Crop side length in pixels (2·radius + 1).
  int size() const { return size_; }
  /// Image coordinates of crop pixel (0, 0).
  int originX() const { return origin_x_; }
  int originY() const { return origin_y_; }
  /// Interleaved [gx, gy] row-major data, size()² · 2 floats.
  const float* data() const { return data_.data(); }

 private:
  std::vector<float> data_;
  int size_ = 0;
  int origin_x_ = 0;
  int origin_y_ = 0;
};

}  // namespace evio::estimator

#include "evio/estimator/frontend/gradient_template.h"

#include <algorithm>
#include <cmath>

#include "evio/core/error.h"

namespace evio::estimator {

namespace {

/// Cubic Hermite spline through p1, p2 with tangents (p2 − p0)/2, (p3 − p1)/2
/// at t ∈ [0, 1]: value and derivative in t, for two channels at once.
inline void hermite(const double* p0, const double* p1, const double* p2, const double* p3, double t,
                    double* f, double* df) {
  for (int k = 0; k < 2; ++k) {
    const double a = 0.5 * (-p0[k] + 3.0 * p1[k] - 3.0 * p2[k] + p3[k]);
    const double b = 0.5 * (2.0 * p0[k] - 5.0 * p1[k] + 4.0 * p2[k] - p3[k]);
    const double c = 0.5 * (-p0[k] + p2[k]);
    f[k] = ((a * t + b) * t + c) * t + p1[k];
    if (df != nullptr) df[k] = (3.0 * a * t + 2.0 * b) * t + c;
  }
}

}  // namespace

void GradientTemplate::assign(const cv::Mat& gx, const cv::Mat& gy, const Vec2& centre, int radius_px) {
  require(gx.type() == CV_32FC1 && gy.type() == CV_32FC1 && gx.size() == gy.size(),
          "GradientTemplate: gradients must be CV_32FC1 of equal size");
  require(radius_px > 0, "GradientTemplate: radius must be > 0");
  size_ = 2 * radius_px + 1;
  origin_x_ = static_cast<int>(std::lround(centre.x())) - radius_px;
  origin_y_ = static_cast<int>(std::lround(centre.y())) - radius_px;
  data_.resize(static_cast<std::size_t>(size_) * static_cast<std::size_t>(size_) * 2);
  for (int r = 0; r < size_; ++r) {
    const int y = std::clamp(origin_y_ + r, 0, gx.rows - 1);
    const float* px = gx.ptr<float>(y);
    const float* py = gy.ptr<float>(y);
    float* dst = data_.data() + static_cast<std::size_t>(r) * static_cast<std::size_t>(size_) * 2;
    for (int c = 0; c < size_; ++c) {
      const int x = std::clamp(origin_x_ + c, 0, gx.cols - 1);
      dst[2 * c] = px[x];
      dst[2 * c + 1] = py[x];
    }
  }
}

void GradientTemplate::sample(const Vec2& x, Vec2* g, Mat2* d_g_d_x) const {
  const double cx = x.x() - origin_x_;
  const double cy = x.y() - origin_y_;
  const double fc = std::floor(cx);
  const double fr = std::floor(cy);
  const int col = static_cast<int>(fc);
  const int row = static_cast<int>(fr);
  const double tc = cx - fc;
  const double tr = cy - fr;
  const int n = size_;
  const auto clampIndex = [n](int i) { return std::clamp(i, 0, n - 1); };
  double rows_f[4][2];
  double rows_dfdc[4][2];
  for (int i = 0; i < 4; ++i) {
    const float* base = data_.data() + static_cast<std::size_t>(clampIndex(row - 1 + i)) * static_cast<std::size_t>(n) * 2;
    double p[4][2];
    for (int j = 0; j < 4; ++j) {
      const float* v = base + 2 * clampIndex(col - 1 + j);
      p[j][0] = v[0];
      p[j][1] = v[1];
    }
    hermite(p[0], p[1], p[2], p[3], tc, rows_f[i], rows_dfdc[i]);
  }
  double f[2];
  double dfdr[2];
  hermite(rows_f[0], rows_f[1], rows_f[2], rows_f[3], tr, f, d_g_d_x != nullptr ? dfdr : nullptr);
  *g = Vec2(f[0], f[1]);
  if (d_g_d_x != nullptr) {
    double dfdc[2];
    hermite(rows_dfdc[0], rows_dfdc[1], rows_dfdc[2], rows_dfdc[3], tr, dfdc, nullptr);
    (*d_g_d_x) << dfdc[0], dfdr[0], dfdc[1], dfdr[1];
  }
}

}  // namespace evio::estimator

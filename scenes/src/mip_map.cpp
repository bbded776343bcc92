#include "evio/scenes/mip_map.h"

#include <algorithm>
#include <cmath>

#include "evio/core/error.h"

namespace evio::scenes {

MipMap::MipMap(const cv::Mat& image, bool repeat) : repeat_(repeat) {
  require(!image.empty() && image.type() == CV_32FC1, "MipMap: expected a non-empty CV_32FC1 image");
  levels_.push_back(image.clone());
  while (levels_.back().cols > 1 || levels_.back().rows > 1) {
    const cv::Mat& a = levels_.back();
    const int w = std::max(1, a.cols / 2), h = std::max(1, a.rows / 2);
    cv::Mat b(h, w, CV_32FC1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        // Source block: 2 × 2, widened to 3 at an odd last row/column.
        const int x0 = 2 * x, y0 = 2 * y;
        const int x1 = (x == w - 1) ? a.cols : std::min(a.cols, x0 + 2);
        const int y1 = (y == h - 1) ? a.rows : std::min(a.rows, y0 + 2);
        double sum = 0.0;
        for (int yy = y0; yy < y1; ++yy)
          for (int xx = x0; xx < x1; ++xx) sum += static_cast<double>(a.at<float>(yy, xx));
        b.at<float>(y, x) = static_cast<float>(sum / ((x1 - x0) * (y1 - y0)));
      }
    levels_.push_back(b);
  }
}

float MipMap::bilinear(int level, float s, float t) const {
  const cv::Mat& m = levels_[static_cast<std::size_t>(level)];
  // Level-0 coordinates to this level's, texel centres at integers.
  const float x = s * static_cast<float>(m.cols) / static_cast<float>(levels_[0].cols) - 0.5f;
  const float y = t * static_cast<float>(m.rows) / static_cast<float>(levels_[0].rows) - 0.5f;
  const float fx0 = std::floor(x), fy0 = std::floor(y);
  const float fx = x - fx0, fy = y - fy0;
  int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  int x1 = x0 + 1, y1 = y0 + 1;
  if (repeat_) {
    const auto wrap = [](int i, int n) {
      i %= n;
      return i < 0 ? i + n : i;
    };
    x0 = wrap(x0, m.cols);
    x1 = wrap(x1, m.cols);
    y0 = wrap(y0, m.rows);
    y1 = wrap(y1, m.rows);
  } else {
    x0 = std::clamp(x0, 0, m.cols - 1);
    x1 = std::clamp(x1, 0, m.cols - 1);
    y0 = std::clamp(y0, 0, m.rows - 1);
    y1 = std::clamp(y1, 0, m.rows - 1);
  }
  const float* r0 = m.ptr<float>(y0);
  const float* r1 = m.ptr<float>(y1);
  const float a = r0[x0] + fx * (r0[x1] - r0[x0]);
  const float b = r1[x0] + fx * (r1[x1] - r1[x0]);
  return a + fy * (b - a);
}

float MipMap::sample(float s, float t, float footprint) const {
  if (!(footprint > 1.0f)) return bilinear(0, s, t);
  const float lambda = std::log2(footprint);
  const int top = levels() - 1;
  const int l0 = std::min(static_cast<int>(lambda), top);
  if (l0 >= top) return bilinear(top, s, t);
  const float f = lambda - static_cast<float>(l0);
  const float a = bilinear(l0, s, t);
  return a + f * (bilinear(l0 + 1, s, t) - a);
}

}  // namespace evio::scenes

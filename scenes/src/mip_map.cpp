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
  for (const cv::Mat& m : levels_)
    table_.push_back(Level{m.data, m.step[0], m.cols, m.rows, static_cast<float>(m.cols), static_cast<float>(m.rows)});
  fcols0_ = table_[0].fcols;
  frows0_ = table_[0].frows;
}

}  // namespace evio::scenes

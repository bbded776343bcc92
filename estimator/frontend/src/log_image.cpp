#include "evio/estimator/frontend/log_image.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "evio/core/error.h"

namespace evio::estimator {

cv::Mat toLogImage(const cv::Mat& image, double offset) {
  require(!image.empty(), "toLogImage: empty image");
  if (image.type() == CV_32FC1) return image;
  require(image.type() == CV_8UC1, "toLogImage: image must be CV_8UC1 or CV_32FC1");
  // 256-entry lookup table: one log per grey level.
  float table[256];
  for (int i = 0; i < 256; ++i) table[i] = static_cast<float>(std::log(i / 255.0 + offset));
  cv::Mat out(image.size(), CV_32FC1);
  for (int r = 0; r < image.rows; ++r) {
    const std::uint8_t* src = image.ptr<std::uint8_t>(r);
    float* dst = out.ptr<float>(r);
    for (int c = 0; c < image.cols; ++c) dst[c] = table[src[c]];
  }
  return out;
}

void imageGradient(const cv::Mat& image, cv::Mat* gx, cv::Mat* gy) {
  require(image.type() == CV_32FC1, "imageGradient: image must be CV_32FC1");
  cv::Sobel(image, *gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(image, *gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
}

cv::Mat toEightBit(const cv::Mat& image) {
  require(!image.empty(), "toEightBit: empty image");
  if (image.type() == CV_8UC1) return image;
  require(image.type() == CV_32FC1, "toEightBit: image must be CV_8UC1 or CV_32FC1");
  std::vector<float> values;
  values.reserve(image.total());
  for (int r = 0; r < image.rows; ++r) {
    const float* row = image.ptr<float>(r);
    for (int c = 0; c < image.cols; ++c)
      if (std::isfinite(row[c])) values.push_back(row[c]);
  }
  if (values.empty()) return cv::Mat::zeros(image.size(), CV_8UC1);
  const auto at = [&](double q) {
    const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
    return static_cast<double>(values[k]);
  };
  const double lo = at(0.01);
  const double hi = at(0.99);
  const double scale = hi > lo ? 255.0 / (hi - lo) : 0.0;
  cv::Mat out;
  image.convertTo(out, CV_8UC1, scale, -lo * scale);  // saturate_cast clamps; NaN → 0
  return out;
}

}  // namespace evio::estimator

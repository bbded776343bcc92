#include "evio/estimator/frontend/feature_detection.h"

#include <algorithm>
#include <cmath>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "evio/core/error.h"

namespace evio::estimator {

namespace {

/// 255 where detection is allowed: inside the border and outside the boxes.
cv::Mat detectionMask(cv::Size size, int border_px, const std::vector<Vec2>& existing, double min_distance_px) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8UC1);
  const int w = size.width - 2 * border_px;
  const int h = size.height - 2 * border_px;
  if (w <= 0 || h <= 0) return mask;
  mask(cv::Rect(border_px, border_px, w, h)).setTo(255);
  const int r = static_cast<int>(std::ceil(min_distance_px));
  for (const Vec2& p : existing) {
    const int cx = static_cast<int>(std::lround(p.x()));
    const int cy = static_cast<int>(std::lround(p.y()));
    const cv::Rect box = cv::Rect(cx - r, cy - r, 2 * r + 1, 2 * r + 1) & cv::Rect(0, 0, size.width, size.height);
    if (box.area() > 0) mask(box).setTo(0);
  }
  return mask;
}

}  // namespace

std::vector<Vec2> detectHarris(const cv::Mat& image8, const std::vector<Vec2>& existing,
                               const HarrisSettings& s) {
  require(image8.type() == CV_8UC1, "detectHarris: image must be CV_8UC1");
  std::vector<Vec2> out;
  if (s.max_corners <= 0) return out;
  const cv::Mat mask = detectionMask(image8.size(), s.border_px, existing, s.min_distance_px);
  std::vector<cv::Point2f> corners;
  cv::goodFeaturesToTrack(image8, corners, s.max_corners, s.quality_level, s.min_distance_px, mask,
                          s.block_size, /*useHarrisDetector=*/true, s.k);
  out.reserve(corners.size());
  for (const auto& c : corners) out.emplace_back(c.x, c.y);
  return out;
}

std::vector<Vec2> detectFast(const cv::Mat& image8, const std::vector<Vec2>& existing, const FastSettings& s) {
  require(image8.type() == CV_8UC1, "detectFast: image must be CV_8UC1");
  std::vector<Vec2> out;
  if (s.max_corners <= 0) return out;
  std::vector<cv::KeyPoint> keypoints;
  cv::FAST(image8, keypoints, s.threshold, s.nonmax_suppression);
  std::stable_sort(keypoints.begin(), keypoints.end(),
                   [](const cv::KeyPoint& a, const cv::KeyPoint& b) { return a.response > b.response; });
  cv::Mat mask = detectionMask(image8.size(), s.border_px, existing, s.min_distance_px);
  const int r = static_cast<int>(std::ceil(s.min_distance_px));
  for (const auto& kp : keypoints) {
    if (static_cast<int>(out.size()) >= s.max_corners) break;
    const int x = static_cast<int>(std::lround(kp.pt.x));
    const int y = static_cast<int>(std::lround(kp.pt.y));
    if (x < 0 || y < 0 || x >= mask.cols || y >= mask.rows || mask.at<std::uint8_t>(y, x) == 0) continue;
    out.emplace_back(kp.pt.x, kp.pt.y);
    const cv::Rect box = cv::Rect(x - r, y - r, 2 * r + 1, 2 * r + 1) & cv::Rect(0, 0, mask.cols, mask.rows);
    mask(box).setTo(0);
  }
  return out;
}

}  // namespace evio::estimator

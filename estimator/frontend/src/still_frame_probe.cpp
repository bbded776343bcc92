#include "evio/estimator/frontend/still_frame_probe.h"

#include <opencv2/video/tracking.hpp>

#include "evio/estimator/frontend/feature_detection.h"
#include "evio/estimator/frontend/log_image.h"

namespace evio::estimator {

StillFrameProbe::StillFrameProbe(double duration_s, int max_corners)
    : duration_ns_(duration_s > 0.0 ? secondsToNs(duration_s) : 0), max_corners_(max_corners) {}

std::optional<FrameCorners> StillFrameProbe::addFrame(TimeNs t_ns, const cv::Mat& image) {
  if (duration_ns_ <= 0 || (first_t_ns_ && t_ns - *first_t_ns_ > duration_ns_)) return std::nullopt;
  const cv::Mat image8 = toEightBit(image);
  FrameCorners out;
  out.t_ns = t_ns;
  if (!first_t_ns_) {
    first_t_ns_ = t_ns;
    HarrisSettings hs;  // 10 px apart, off the border, down to 1 % of the best response
    hs.max_corners = max_corners_;
    hs.quality_level = 0.01;
    hs.min_distance_px = 10.0;
    hs.border_px = 10;
    for (const Vec2& c : detectHarris(image8, {}, hs)) corners_.emplace_back(static_cast<float>(c.x()), static_cast<float>(c.y()));
    if (corners_.empty()) return std::nullopt;
    first_ = image8.clone();
    for (std::size_t i = 0; i < corners_.size(); ++i)
      out.corners_px.emplace_back(static_cast<FeatureId>(i), Vec2(corners_[i].x, corners_[i].y));
    return out;
  }
  if (corners_.empty()) return std::nullopt;
  // Forward from the first frame, then back from what was found: a corner
  // counts only if it comes back to within kForwardBackwardPx of where it
  // started. Lucas–Kanade on a corner of noise (a dark, textureless pad
  // has only those) converges somewhere tens of pixels off; its way back
  // does not retrace it.
  constexpr float kForwardBackwardPx = 0.5f;
  std::vector<cv::Point2f> found, back;
  std::vector<std::uint8_t> status, status_back;
  std::vector<float> error;
  const cv::Size window(21, 21);
  cv::calcOpticalFlowPyrLK(first_, image8, corners_, found, status, error, window, 3);
  cv::calcOpticalFlowPyrLK(image8, first_, found, back, status_back, error, window, 3);
  for (std::size_t i = 0; i < corners_.size(); ++i) {
    const cv::Point2f d = back[i] - corners_[i];
    if (status[i] != 0 && status_back[i] != 0 && d.x * d.x + d.y * d.y <= kForwardBackwardPx * kForwardBackwardPx)
      out.corners_px.emplace_back(static_cast<FeatureId>(i), Vec2(found[i].x, found[i].y));
  }
  return out;
}

}  // namespace evio::estimator

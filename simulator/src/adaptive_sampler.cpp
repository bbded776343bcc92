#include "evio/simulator/adaptive_sampler.h"

#include <algorithm>
#include <cmath>

#include "evio/core/error.h"

namespace evio::simulator {

void AdaptiveSampler::Options::validate() const {
  requireInRange("lambda", lambda, 1e-3, 10.0);
  requireInRange("min_rate_hz", min_rate_hz, 1e-3, 1e5);
  requireInRange("max_rate_hz", max_rate_hz, 1e-3, 1e5);
  requireField(max_rate_hz >= min_rate_hz, "max_rate_hz", "must be >= min_rate_hz");
  requireInRange("tile_px", tile_px, 1, 1024);
}

AdaptiveSampler::AdaptiveSampler(const Options& options, double threshold, double log_eps)
    : options_(options), threshold_(threshold), log_eps_(static_cast<float>(log_eps)) {
  options_.validate();
  requirePositive("threshold", threshold);
  requirePositive("log_eps", log_eps);
  min_interval_ns_ = std::max<TimeNs>(1, secondsToNs(1.0 / options_.max_rate_hz));
  max_interval_ns_ = std::max<TimeNs>(min_interval_ns_, secondsToNs(1.0 / options_.min_rate_hz));
}

cv::Mat AdaptiveSampler::logImage(const cv::Mat& radiance) const {
  require(radiance.type() == CV_32FC1, "AdaptiveSampler: radiance must be CV_32FC1");
  cv::Mat out(radiance.size(), CV_32FC1);
  for (int y = 0; y < radiance.rows; ++y) {
    const float* in = radiance.ptr<float>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < radiance.cols; ++x) o[x] = std::log(log_eps_ + (in[x] > 0.0f ? in[x] : 0.0f));
  }
  return out;
}

float AdaptiveSampler::logRateAt(const cv::Mat& log_image, const cv::Mat& flow, int x, int y) const {
  const int w = log_image.cols, h = log_image.rows;
  const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
  float rate = 0.0f;
  if (options_.rate_bound) {
    const float l = log_image.at<float>(y, x);
    float slope = 0.0f;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = x + dx, qy = y + dy;
        if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= w || qy >= h) continue;
        const float d = std::abs(log_image.at<float>(qy, qx) - l) * (dx != 0 && dy != 0 ? 0.70710678f : 1.0f);
        if (d > slope) slope = d;  // NaN never wins
      }
    // The steepest of 8 directions is within 22.5° of ∇L: slope / cos 22.5° >= ‖∇L‖ for linear L.
    rate = slope * 1.0823922f * std::sqrt(f[0] * f[0] + f[1] * f[1]);
  } else {
    const int x0 = std::max(0, x - 1), x1 = std::min(w - 1, x + 1);
    const int y0 = std::max(0, y - 1), y1 = std::min(h - 1, y + 1);
    const float gx = x1 > x0 ? (log_image.at<float>(y, x1) - log_image.at<float>(y, x0)) / static_cast<float>(x1 - x0)
                             : 0.0f;
    const float gy = y1 > y0 ? (log_image.at<float>(y1, x) - log_image.at<float>(y0, x)) / static_cast<float>(y1 - y0)
                             : 0.0f;
    rate = std::abs(gx * f[0] + gy * f[1]);
  }
  return std::isfinite(rate) ? rate : 0.0f;
}

TimeNs AdaptiveSampler::interval(float log_rate) const {
  const double rate = static_cast<double>(log_rate);
  if (!(rate > 0.0)) return max_interval_ns_;
  const double dt_ns = options_.lambda * threshold_ / rate * 1e9;
  if (dt_ns >= static_cast<double>(max_interval_ns_)) return max_interval_ns_;
  return std::max(min_interval_ns_, static_cast<TimeNs>(dt_ns));
}

void AdaptiveSampler::schedule(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow,
                               std::vector<TimeNs>* next_ns) const {
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "AdaptiveSampler::schedule: flow must be CV_32FC2 of the radiance's size");
  const cv::Mat l = logImage(radiance);
  const int w = radiance.cols, h = radiance.rows;
  next_ns->resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  const int tile = options_.tile_px;
  for (int ty = 0; ty < h; ty += tile) {
    for (int tx = 0; tx < w; tx += tile) {
      const int ye = std::min(h, ty + tile), xe = std::min(w, tx + tile);
      TimeNs tile_dt = max_interval_ns_;
      for (int y = ty; y < ye; ++y)
        for (int x = tx; x < xe; ++x) {
          const TimeNs dt = interval(logRateAt(l, flow, x, y));
          if (tile == 1) {
            (*next_ns)[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
                t_ns + dt;
          }
          tile_dt = std::min(tile_dt, dt);
        }
      if (tile > 1)
        for (int y = ty; y < ye; ++y)
          for (int x = tx; x < xe; ++x)
            (*next_ns)[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)] =
                t_ns + tile_dt;
    }
  }
}

TimeNs AdaptiveSampler::wholeFrameInterval(const cv::Mat& radiance, const cv::Mat& flow) const {
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "AdaptiveSampler::wholeFrameInterval: flow must be CV_32FC2 of the radiance's size");
  const cv::Mat l = logImage(radiance);
  float max_rate = 0.0f;
  for (int y = 0; y < radiance.rows; ++y)
    for (int x = 0; x < radiance.cols; ++x) max_rate = std::max(max_rate, logRateAt(l, flow, x, y));
  return interval(max_rate);
}

}  // namespace evio::simulator

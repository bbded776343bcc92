#include "evio/estimator/frontend/image_reconstructor.h"

#include <cmath>

#include "evio/core/error.h"
#include "evio/estimator/frontend/davis_thresholds.h"

namespace evio::estimator {

void ImageReconstructorOptions::validate() const {
  requireNonNegative("cutoff_frequency_rad_s", cutoff_frequency_rad_s);
  requireNonNegative("contrast_threshold", contrast_threshold);
  requireNonNegative("contrast_threshold_neg", contrast_threshold_neg);
  requireField(saturation_low >= 0 && saturation_low < saturation_high && saturation_high <= 255,
               "saturation_high", "need 0 <= saturation_low < saturation_high <= 255");
  requirePositive("log_offset", log_offset);
  requireField(output_every_events >= 0, "output_every_events", "must be >= 0");
  requireInRange("output_rate_hz", output_rate_hz, 0.0, 1e5);  // images per second
}

ImageReconstructor::ImageReconstructor(const ImageReconstructorOptions& options, int width, int height)
    : options_(options), width_(width), height_(height) {
  options_.validate();
  require(width > 0 && height > 0, "ImageReconstructor: size must be > 0");
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  state_.assign(n, 0.0f);
  frame_log_.assign(n, 0.0f);
  last_t_ns_.assign(n, 0);
}

std::size_t ImageReconstructor::addEvents(const EventArray& events, std::size_t begin, std::size_t end) {
  const auto& t = events.t();
  const auto& x = events.x();
  const auto& y = events.y();
  const auto& p = events.p();
  const double alpha = options_.cutoff_frequency_rad_s;
  // Unresolved zeros (a caller that skipped resolveSensorParameters): the DAVIS240C's steps.
  const double c_on = options_.contrast_threshold > 0.0 ? options_.contrast_threshold : kDavis240cThresholdOn;
  const double c_off = options_.contrast_threshold_neg > 0.0 ? options_.contrast_threshold_neg
                       : options_.contrast_threshold > 0.0 ? options_.contrast_threshold
                                                           : kDavis240cThresholdOff;
  const float step_on = static_cast<float>(c_on);
  const float step_off = static_cast<float>(c_off);
  const TimeNs period_ns = options_.output_rate_hz > 0.0 ? secondsToNs(1.0 / options_.output_rate_hz) : 0;
  for (std::size_t i = begin; i < end; ++i) {
    require(x[i] < width_ && y[i] < height_, "ImageReconstructor: event outside the sensor");
    const std::size_t k = static_cast<std::size_t>(y[i]) * static_cast<std::size_t>(width_) + x[i];
    const double dt = nsToSeconds(t[i] - last_t_ns_[k]);
    const float decay = dt > 0.0 ? static_cast<float>(std::exp(-alpha * dt)) : 1.0f;
    state_[k] = frame_log_[k] + (state_[k] - frame_log_[k]) * decay + (p[i] != 0 ? step_on : -step_off);
    last_t_ns_[k] = t[i];
    ++events_since_output_;
    bool due = options_.output_every_events > 0 &&
               events_since_output_ >= static_cast<std::uint64_t>(options_.output_every_events);
    if (period_ns > 0) {
      if (next_output_t_ns_ < 0) next_output_t_ns_ = t[i] + period_ns;
      if (t[i] >= next_output_t_ns_) {
        due = true;
        while (next_output_t_ns_ <= t[i]) next_output_t_ns_ += period_ns;
      }
    }
    if (due) {
      due_ = true;
      due_t_ns_ = t[i];
      events_since_output_ = 0;
      return i + 1;
    }
  }
  return end;
}

void ImageReconstructor::addFrame(TimeNs t_ns, const cv::Mat& image) {
  if (!options_.fuse_frames) return;
  require(image.type() == CV_8UC1 && image.cols == width_ && image.rows == height_,
          "ImageReconstructor: frames must be CV_8UC1 of the sensor size");
  const double alpha = options_.cutoff_frequency_rad_s;
  float table[256];
  for (int i = 0; i < 256; ++i) table[i] = static_cast<float>(std::log(i / 255.0 + options_.log_offset));
  for (int r = 0; r < height_; ++r) {
    const std::uint8_t* row = image.ptr<std::uint8_t>(r);
    for (int c = 0; c < width_; ++c) {
      const std::size_t k = static_cast<std::size_t>(r) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(c);
      // Bring the estimate to t_ns under the old L_F, then switch L_F.
      const double dt = nsToSeconds(t_ns - last_t_ns_[k]);
      if (dt > 0.0) {
        state_[k] = frame_log_[k] + (state_[k] - frame_log_[k]) * static_cast<float>(std::exp(-alpha * dt));
        last_t_ns_[k] = t_ns;
      }
      if (row[c] > options_.saturation_low && row[c] < options_.saturation_high) {
        frame_log_[k] = table[row[c]];
        if (!any_frame_) state_[k] = frame_log_[k];  // start from the first frame
      }
    }
  }
  any_frame_ = true;
}

cv::Mat ImageReconstructor::image(TimeNs t_ns) {
  due_ = false;
  const double alpha = options_.cutoff_frequency_rad_s;
  cv::Mat out(height_, width_, CV_32FC1);
  for (int r = 0; r < height_; ++r) {
    float* dst = out.ptr<float>(r);
    for (int c = 0; c < width_; ++c) {
      const std::size_t k = static_cast<std::size_t>(r) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(c);
      const double dt = nsToSeconds(t_ns - last_t_ns_[k]);
      const float decay = dt > 0.0 ? static_cast<float>(std::exp(-alpha * dt)) : 1.0f;
      dst[c] = frame_log_[k] + (state_[k] - frame_log_[k]) * decay;
    }
  }
  return out;
}

}  // namespace evio::estimator

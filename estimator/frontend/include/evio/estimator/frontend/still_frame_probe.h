#pragma once
/// @file still_frame_probe.h
/// The frames' word on rest for the backend's first window
/// (pipeline/gyro_bias_window.h, docs/algorithms.md#still-until-it-moves):
/// Harris corners of the first frame, found again in each later frame of
/// the first duration_s by pyramidal Lucas–Kanade from the first frame (not
/// frame to frame: a still camera's corners stay put to hundredths of a
/// pixel, and errors do not add up), each kept only if tracking it back
/// returns it to within 0.5 px of its start. Independent of the tracker: an event
/// tracker reports nothing while nothing moves, so its own tracks cannot
/// say that nothing moved.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "evio/estimator/measurements.h"

namespace evio::estimator {

class StillFrameProbe {
 public:
  /// duration_s ≤ 0: off (addFrame returns nothing).
  explicit StillFrameProbe(double duration_s, int max_corners = 30);
  /// The corners found in `image` (any type toEightBit takes), from the
  /// first frame on, until duration_s after it; std::nullopt after that or
  /// when the first frame had no corner.
  std::optional<FrameCorners> addFrame(TimeNs t_ns, const cv::Mat& image);

 private:
  TimeNs duration_ns_;
  int max_corners_;
  std::optional<TimeNs> first_t_ns_;
  cv::Mat first_;
  std::vector<cv::Point2f> corners_;
};

}  // namespace evio::estimator

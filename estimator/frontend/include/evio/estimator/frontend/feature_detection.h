#pragma once
/// @file feature_detection.h
/// Corner detection for the frontends: Harris corners (EKLT) and FAST
/// corners (KLT), both avoiding the image border and the neighbourhood of
/// features that are already tracked.

#include <vector>

#include <opencv2/core/mat.hpp>

#include "evio/core/eigen_types.h"

namespace evio::estimator {

struct HarrisSettings {
  int max_corners = 60;          ///< at most this many new corners
  double quality_level = 0.3;    ///< relative to the best corner response
  double min_distance_px = 9.0;  ///< between corners, and to existing features
  int block_size = 3;            ///< Harris window
  double k = 0.04;               ///< Harris k
  int border_px = 9;             ///< no corner closer than this to the image edge
};

/// Harris corners of an 8-bit image (cv::goodFeaturesToTrack with the Harris
/// response), excluding a box of ±min_distance_px around every point of
/// `existing`. Strongest first.
std::vector<Vec2> detectHarris(const cv::Mat& image8, const std::vector<Vec2>& existing,
                               const HarrisSettings& settings);

struct FastSettings {
  int max_corners = 60;          ///< at most this many new corners
  int threshold = 20;            ///< FAST intensity threshold (grey levels)
  bool nonmax_suppression = true;
  double min_distance_px = 9.0;  ///< between corners, and to existing features
  int border_px = 10;            ///< no corner closer than this to the image edge
};

/// FAST corners of an 8-bit image, strongest response first, greedily
/// thinned to min_distance_px and kept away from `existing`.
std::vector<Vec2> detectFast(const cv::Mat& image8, const std::vector<Vec2>& existing,
                             const FastSettings& settings);

}  // namespace evio::estimator

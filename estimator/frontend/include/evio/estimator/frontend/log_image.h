#pragma once
/// @file log_image.h
/// The log image EKLT works on and its gradient.

#include <opencv2/core/mat.hpp>

namespace evio::estimator {

/// Log image L = log(I/255 + offset) of an 8-bit frame (CV_8UC1), as CV_32FC1.
/// A CV_32FC1 input is taken as a log image already and returned as is
/// (shared data). Throws evio::Error for other types or an empty image.
cv::Mat toLogImage(const cv::Mat& image, double offset = 0.01);

/// Gradient of a CV_32FC1 image in units per pixel: the 3×3 Sobel operator
/// divided by 8, i.e. ∂L/∂x ≈ (L(x+1) − L(x−1))/2 smoothed across rows, with
/// replicated borders. x right, y down.
void imageGradient(const cv::Mat& image, cv::Mat* gx, cv::Mat* gy);

/// An 8-bit view of any frame for OpenCV detectors and Lucas–Kanade: CV_8UC1
/// is returned as is; CV_32FC1 is mapped linearly from its [1 %, 99 %]
/// percentile range onto [0, 255] (saturating outside).
cv::Mat toEightBit(const cv::Mat& image);

}  // namespace evio::estimator

#pragma once
/// @file render_output.h
/// Writing a RenderOutput: EXR images of the physical quantities and an
/// 8-bit tone-mapped preview.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "evio/simulator/renderer.h"

namespace evio::simulator {

/// The radiance that maps to white in auto mode: the 99.5th percentile of
/// the finite radiance values (0 → 1 when the image is black).
double autoWhite(const cv::Mat& radiance);

/// 8-bit preview: v = round(255 · clamp(L / white, 0, 1)^(1/2.2)), white in
/// W/(m²·sr); white <= 0 selects autoWhite(radiance).
cv::Mat toneMap(const cv::Mat& radiance, double white_w_m2_sr = 0.0);

/// Writes into `dir` (created if missing), each file atomically:
///   radiance.exr  channel Y, W/(m²·sr)
///   depth.exr     channel Z, m along the optical axis (+inf: no surface)
///   normal.exr    channels X, Y, Z, world frame
///   flow.exr      channels U, V, px/s (only when out.flow is set)
///   preview.png   toneMap(radiance, white_w_m2_sr)
/// Returns the paths written.
std::vector<std::string> writeRenderOutput(const std::string& dir, const RenderOutput& out,
                                           double white_w_m2_sr = 0.0);

}  // namespace evio::simulator

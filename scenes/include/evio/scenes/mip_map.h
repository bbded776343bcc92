#pragma once
/// @file mip_map.h
/// A mip-mapped single-channel float texture with trilinear filtering: the
/// antialiased lookup of images and of baked procedural textures.
///
/// Level 0 is the image; level l+1 averages 2 × 2 texels of level l (an odd
/// last row or column is averaged in with the previous one). Texel (i, j) of
/// level l covers [i, i+1) × [j, j+1) · 2^l in level-0 texel units. A lookup
/// at level-0 coordinates (s, t) with a pixel footprint of f texels reads
/// level λ = log2(max(f, 1)) by bilinear interpolation between texel
/// centres on levels ⌊λ⌋ and ⌊λ⌋ + 1 and blends them linearly.

#include <vector>

#include <opencv2/core/mat.hpp>

namespace evio::scenes {

class MipMap {
 public:
  MipMap() = default;
  /// `image` CV_32FC1, non-empty. `repeat`: tile the image, else clamp to the edge.
  MipMap(const cv::Mat& image, bool repeat);

  /// Trilinear lookup at level-0 texel coordinates (s, t) (texel centres at
  /// i + 0.5) with a footprint of `footprint` level-0 texels.
  float sample(float s, float t, float footprint) const;

  int levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int l) const { return levels_[static_cast<std::size_t>(l)]; }

 private:
  float bilinear(int level, float s, float t) const;
  std::vector<cv::Mat> levels_;
  bool repeat_ = true;
};

}  // namespace evio::scenes

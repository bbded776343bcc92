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

#include <algorithm>
#include <cmath>
#include <cstddef>
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

  /// sample() of eight points at once with AVX2 (only on a CPU that has it):
  /// out[k] = sample(s[k], t[k], footprint[k]), bit for bit. Lanes that need
  /// wrapping or clamping go through sample() itself.
  void sample8Avx2(const float* s, const float* t, const float* footprint, float* out) const;

  int levels() const { return static_cast<int>(levels_.size()); }
  const cv::Mat& level(int l) const { return levels_[static_cast<std::size_t>(l)]; }

 private:
  /// One level as the lookup reads it (pointers into levels_, whose buffers
  /// copies of the MipMap share).
  struct Level {
    const unsigned char* data = nullptr;
    std::size_t step = 0;  ///< bytes per row
    int cols = 0, rows = 0;
    float fcols = 0.0f, frows = 0.0f;
  };
  float bilinear(int level, float s, float t) const;
  cv::Mat texels_;               ///< every level's texels, level after level, rows unpadded (1 × N), + one 0
  std::vector<cv::Mat> levels_;  ///< views into texels_
  std::vector<Level> table_;
  /// Per level, as the 8-lane lookup gathers them: first texel in texels_,
  /// columns, rows, and the same as floats.
  std::vector<int> first_, cols_, rows_;
  std::vector<float> fcols_, frows_;
  float fcols0_ = 0.0f, frows0_ = 0.0f;  ///< level-0 size as floats
  bool repeat_ = true;
};

// Lookups, inline for the renderer's inner loop.

inline float MipMap::bilinear(int level, float s, float t) const {
  const Level& m = table_[static_cast<std::size_t>(level)];
  // Level-0 coordinates to this level's, texel centres at integers.
  const float x = s * m.fcols / fcols0_ - 0.5f;
  const float y = t * m.frows / frows0_ - 0.5f;
  const float fx0 = std::floor(x), fy0 = std::floor(y);
  const float fx = x - fx0, fy = y - fy0;
  int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  int x1 = x0 + 1, y1 = y0 + 1;
  if (x0 >= 0 && x1 < m.cols && y0 >= 0 && y1 < m.rows) {
    // Inside the level (the common case): no wrapping or clamping.
  } else if (repeat_) {
    const auto wrap = [](int i, int n) {
      i %= n;
      return i < 0 ? i + n : i;
    };
    x0 = wrap(x0, m.cols);
    x1 = wrap(x1, m.cols);
    y0 = wrap(y0, m.rows);
    y1 = wrap(y1, m.rows);
  } else {
    x0 = std::clamp(x0, 0, m.cols - 1);
    x1 = std::clamp(x1, 0, m.cols - 1);
    y0 = std::clamp(y0, 0, m.rows - 1);
    y1 = std::clamp(y1, 0, m.rows - 1);
  }
  const auto* r0 = reinterpret_cast<const float*>(m.data + static_cast<std::size_t>(y0) * m.step);
  const auto* r1 = reinterpret_cast<const float*>(m.data + static_cast<std::size_t>(y1) * m.step);
  const float a = r0[x0] + fx * (r0[x1] - r0[x0]);
  const float b = r1[x0] + fx * (r1[x1] - r1[x0]);
  return a + fy * (b - a);
}

inline float MipMap::sample(float s, float t, float footprint) const {
  if (!(footprint > 1.0f)) return bilinear(0, s, t);
  const float lambda = std::log2(footprint);
  const int top = levels() - 1;
  if (!(lambda < static_cast<float>(top))) return bilinear(top, s, t);  // also an infinite footprint
  const int l0 = static_cast<int>(lambda);
  const float f = lambda - static_cast<float>(l0);
  const float a = bilinear(l0, s, t);
  return a + f * (bilinear(l0 + 1, s, t) - a);
}

}  // namespace evio::scenes

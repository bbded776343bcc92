#pragma once
/// @file feature_grid.h
/// Event → feature lookup for EKLT: one bit per feature slot at every pixel,
/// set over the rectangle of pixels whose events reach the slot's patch. An
/// event costs one read of ceil(slots/64) words; moving a patch rewrites only
/// its own bits. Memory: width · height · ceil(slots/64) · 8 bytes, fixed.

#include <cstdint>
#include <vector>

namespace evio::estimator {

/// An inclusive pixel rectangle [x0, x1] × [y0, y1]; empty when x1 < x0.
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0 || y1 < y0; }
};

class FeatureGrid {
 public:
  FeatureGrid(int width, int height, int num_slots);

  /// Clears the bits of `slot` over `old_rect`, then sets them over `new_rect`
  /// (both clipped to the image).
  void move(int slot, const PixelRect& old_rect, const PixelRect& new_rect);

  /// The words of pixel (x, y): bit b of word k is slot 64·k + b.
  const std::uint64_t* at(int x, int y) const {
    return bits_.data() + (static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x)) * words_;
  }
  int words() const { return static_cast<int>(words_); }
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  void apply(int slot, const PixelRect& rect, bool set);
  int width_;
  int height_;
  std::size_t words_;
  std::vector<std::uint64_t> bits_;
};

}  // namespace evio::estimator

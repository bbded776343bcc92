#include "evio/estimator/frontend/feature_grid.h"

#include <algorithm>

#include "evio/core/error.h"

namespace evio::estimator {

FeatureGrid::FeatureGrid(int width, int height, int num_slots)
    : width_(width), height_(height), words_(static_cast<std::size_t>((num_slots + 63) / 64)) {
  require(width > 0 && height > 0 && num_slots > 0, "FeatureGrid: size and slots must be > 0");
  bits_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * words_, 0);
}

void FeatureGrid::move(int slot, const PixelRect& old_rect, const PixelRect& new_rect) {
  apply(slot, old_rect, false);
  apply(slot, new_rect, true);
}

void FeatureGrid::apply(int slot, const PixelRect& rect, bool set) {
  const int x0 = std::max(rect.x0, 0);
  const int y0 = std::max(rect.y0, 0);
  const int x1 = std::min(rect.x1, width_ - 1);
  const int y1 = std::min(rect.y1, height_ - 1);
  if (x1 < x0 || y1 < y0) return;
  const std::size_t word = static_cast<std::size_t>(slot) / 64;
  const std::uint64_t mask = std::uint64_t{1} << (static_cast<unsigned>(slot) % 64);
  for (int y = y0; y <= y1; ++y) {
    std::uint64_t* row = bits_.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) * words_ + word;
    for (int x = x0; x <= x1; ++x) {
      std::uint64_t& w = row[static_cast<std::size_t>(x) * words_];
      w = set ? (w | mask) : (w & ~mask);
    }
  }
}

}  // namespace evio::estimator

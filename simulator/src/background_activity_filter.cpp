#include "evio/simulator/background_activity_filter.h"

#include <limits>
#include <string>

#include "evio/core/error.h"

namespace evio::simulator {

BackgroundActivityFilter::BackgroundActivityFilter(int width, int height, TimeNs window_ns)
    : width_(width), height_(height), window_ns_(window_ns) {
  require(width > 0 && height > 0, "BackgroundActivityFilter: width and height must be positive");
  require(window_ns > 0, "BackgroundActivityFilter: window must be positive, got " + std::to_string(window_ns) +
                             " ns");
  // "Never stamped": far enough in the past that t − stamp never fits a window.
  stamp_.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height),
                std::numeric_limits<TimeNs>::min() / 2);
}

bool BackgroundActivityFilter::pass(std::uint16_t x, std::uint16_t y, TimeNs t_ns) {
  const auto w = static_cast<std::size_t>(width_);
  const bool passes = t_ns - stamp_[y * w + x] <= window_ns_;
  const int x0 = x > 0 ? x - 1 : 0, x1 = x + 1 < width_ ? x + 1 : width_ - 1;
  const int y0 = y > 0 ? y - 1 : 0, y1 = y + 1 < height_ ? y + 1 : height_ - 1;
  for (int yy = y0; yy <= y1; ++yy)
    for (int xx = x0; xx <= x1; ++xx)
      if (xx != x || yy != y) stamp_[static_cast<std::size_t>(yy) * w + static_cast<std::size_t>(xx)] = t_ns;
  return passes;
}

}  // namespace evio::simulator

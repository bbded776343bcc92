// EventCamera::updateRects (event_camera.h): whole rectangles of the image
// (the tiles a render loop re-traced) through the vectorised pixel path,
// row run by row run, blocks of runs in parallel.

#include <algorithm>
#include <limits>
#include <string>

#include "evio/core/error.h"
#include "evio/simulator/event_camera.h"
#include "parallel_for.h"

namespace evio::simulator {

namespace {
constexpr std::size_t kRunBlock = 4096;  // pixels per parallel block of runs (about)
}  // namespace

void EventCamera::updateRects(TimeNs t_ns, const std::vector<cv::Rect>& rects, const cv::Mat& radiance) {
  if (radiance.type() != CV_32FC1 || radiance.rows != height_ || radiance.cols != width_ || !radiance.isContinuous())
    throw Error("EventCamera::updateRects: radiance must be a continuous CV_32FC1 image of " + std::to_string(width_) +
                "x" + std::to_string(height_));
  if (!initialized_) throw Error("EventCamera::updateRects: call initialize() or update() first");
  if (uniform_) {
    std::fill(t_prev_.begin(), t_prev_.end(), uniform_t_);
    uniform_ = false;
  }
  const cv::Rect image(0, 0, width_, height_);
  for (const cv::Rect& r : rects)
    if ((r & image) != r) throw Error("EventCamera::updateRects: a rectangle is not inside the image");
  // Runs of one row, [begin, end) pixel indices, checked before any change.
  // Consecutive rectangles on the same rows (a row of tiles, given left to
  // right) give their runs row by row, so that runs_ comes out sorted and
  // needs no sort when the rectangles come in row-major order.
  runs_.clear();
  std::size_t count = 0;
  for (std::size_t g = 0; g < rects.size();) {
    std::size_t g_end = g + 1;
    while (g_end < rects.size() && rects[g_end].y == rects[g].y && rects[g_end].height == rects[g].height) ++g_end;
    for (int y = rects[g].y; y < rects[g].y + rects[g].height; ++y)
      for (std::size_t k = g; k < g_end; ++k) {
        const cv::Rect& r = rects[k];
        const std::size_t begin = static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) +
                                  static_cast<std::size_t>(r.x);
        runs_.emplace_back(begin, begin + static_cast<std::size_t>(r.width));
        TimeNs latest = std::numeric_limits<TimeNs>::min();  // the run's latest sample
        for (std::size_t i = begin; i < begin + static_cast<std::size_t>(r.width); ++i)
          latest = std::max(latest, t_prev_[i]);
        if (t_ns <= latest)
          throw Error("EventCamera::updateRects: time " + std::to_string(t_ns) + " ns is not after the last sample " +
                      std::to_string(latest) + " ns of a pixel in row " + std::to_string(y));
        count += static_cast<std::size_t>(r.width);
      }
    g = g_end;
  }
  if (!std::is_sorted(runs_.begin(), runs_.end())) std::sort(runs_.begin(), runs_.end());
  // Runs that touch (tiles side by side) become one: fewer, longer vector loops.
  std::size_t merged = 0;
  for (std::size_t k = 0; k < runs_.size(); ++k) {
    if (merged > 0 && runs_[k].first < runs_[merged - 1].second)
      throw Error("EventCamera::updateRects: the rectangles overlap");
    if (merged > 0 && runs_[merged - 1].second == runs_[k].first) {
      runs_[merged - 1].second = runs_[k].second;
    } else {
      runs_[merged++] = runs_[k];
    }
  }
  runs_.resize(merged);
  // Blocks of whole runs of about kRunBlock pixels, fixed by the runs alone
  // (not by the thread count); their events are concatenated in block order.
  block_starts_.clear();
  std::size_t in_block = 0;
  for (std::size_t k = 0; k < runs_.size(); ++k) {
    if (k == 0 || in_block >= kRunBlock) {
      block_starts_.push_back(k);
      in_block = 0;
    }
    in_block += runs_[k].second - runs_[k].first;
  }
  block_starts_.push_back(runs_.size());
  const std::size_t blocks = block_starts_.size() - 1;
  if (block_events_.size() < blocks) block_events_.resize(blocks);
  const float* in = radiance.ptr<float>();
  const auto run = [&](std::size_t b) {
    block_events_[b].clear();
    for (std::size_t k = block_starts_[b]; k < block_starts_[b + 1]; ++k) {
      const auto [begin, end] = runs_[k];
      processBlock(begin, end, t_ns, in, &block_events_[b]);
      std::fill(t_prev_.begin() + static_cast<std::ptrdiff_t>(begin), t_prev_.begin() + static_cast<std::ptrdiff_t>(end),
                t_ns);
    }
  };
  parallelFor(options_.threads, blocks, 1, run);
  for (std::size_t b = 0; b < blocks; ++b)
    pending_.insert(pending_.end(), block_events_[b].begin(), block_events_[b].end());
  if (count > 0) t_max_sample_ = std::max(t_max_sample_, t_ns);
  pixel_updates_ += count;
}

}  // namespace evio::simulator

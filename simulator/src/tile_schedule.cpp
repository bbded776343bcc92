#include "evio/simulator/tile_schedule.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "evio/core/error.h"
#include "evio/core/options.h"
#include "parallel_for.h"

namespace evio::simulator {

namespace {
AdaptiveSampler::Options perPixel(AdaptiveSampler::Options o) {
  o.tile_px = 1;  // the tile reduction happens here
  return o;
}
}  // namespace

TileSchedule::TileSchedule(int width, int height, int tile_px, const AdaptiveSampler::Options& sampler,
                           double threshold, double log_eps, TimeNs origin_ns, TimeNs quantum_ns, int threads)
    : width_(width),
      height_(height),
      tile_px_(tile_px),
      sampler_(perPixel(sampler), threshold, log_eps),
      origin_ns_(origin_ns),
      quantum_ns_(quantum_ns),
      threads_(threads) {
  requireInRange("threads", threads, 0, 1024);
  requirePositive("width", width);
  requirePositive("height", height);
  requireInRange("tile_px", tile_px, 1, 1024);
  requireNonNegative("quantum_ns", quantum_ns);
  tiles_x_ = (width + tile_px - 1) / tile_px;
  tiles_y_ = (height + tile_px - 1) / tile_px;
  log_ = cv::Mat(height, width, CV_32FC1, cv::Scalar(0.0f));
  due_.assign(static_cast<std::size_t>(tileCount()), origin_ns);
}

TimeNs TileSchedule::onGrid(TimeNs t_ns, TimeNs interval_ns) const {
  if (quantum_ns_ == 0) return t_ns + interval_ns;
  const auto floorDiv = [](TimeNs a, TimeNs b) { return a >= 0 ? a / b : -((-a + b - 1) / b); };
  const TimeNs at_or_before = origin_ns_ + floorDiv(t_ns + interval_ns - origin_ns_, quantum_ns_) * quantum_ns_;
  const TimeNs after_t = origin_ns_ + (floorDiv(t_ns - origin_ns_, quantum_ns_) + 1) * quantum_ns_;
  return std::max(at_or_before, after_t);
}

void TileSchedule::updateLog(int tile, const cv::Mat& radiance) {
  const cv::Rect r = tileRect(tile);
  for (int y = r.y; y < r.y + r.height; ++y) sampler_.logRow(radiance, y, r.x, r.x + r.width, &log_);
}

float TileSchedule::tileRate(int tile, const cv::Mat& flow) const {
  // The largest AdaptiveSampler::logRateAt of the tile's pixels (each >= 0,
  // non-finite counted as 0), a row at a time.
  const cv::Rect r = tileRect(tile);
  constexpr int kChunk = 64;
  std::array<float, kChunk> rates{};
  float rate = 0.0f;
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; x += kChunk) {
      const int n = std::min(kChunk, r.x + r.width - x);
      sampler_.logRatesOfRow(log_, flow, y, x, x + n, rates.data());
      for (int i = 0; i < n; ++i) rate = std::max(rate, rates[static_cast<std::size_t>(i)]);
    }
  return rate;
}

void TileSchedule::reschedule(int tile, TimeNs t_ns, const cv::Mat& flow) {
  due_[static_cast<std::size_t>(tile)] = onGrid(t_ns, sampler_.interval(tileRate(tile, flow)));
}

template <class F>
void TileSchedule::forTiles(std::size_t count, const F& f) const {
  parallelFor(threads_, count, 16, f);
}

void TileSchedule::scheduleAll(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_,
          "TileSchedule: radiance must be CV_32FC1 of the schedule's size");
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "TileSchedule: flow must be CV_32FC2 of the radiance's size");
  // All logs first: a tile's rate reads its neighbours' new samples.
  const auto n = static_cast<std::size_t>(tileCount());
  forTiles(n, [&](std::size_t k) { updateLog(static_cast<int>(k), radiance); });
  forTiles(n, [&](std::size_t k) { reschedule(static_cast<int>(k), t_ns, flow); });
}

void TileSchedule::scheduleTiles(TimeNs t_ns, const std::vector<int>& tiles, const cv::Mat& radiance,
                                 const cv::Mat& flow) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_,
          "TileSchedule: radiance must be CV_32FC1 of the schedule's size");
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "TileSchedule: flow must be CV_32FC2 of the radiance's size");
  for (const int k : tiles)
    if (k < 0 || k >= tileCount()) throw Error("TileSchedule: tile " + std::to_string(k) + " out of range");
  // All logs first: a tile's rate reads its neighbours' new samples.
  forTiles(tiles.size(), [&](std::size_t i) { updateLog(tiles[i], radiance); });
  forTiles(tiles.size(), [&](std::size_t i) { reschedule(tiles[i], t_ns, flow); });
}

TimeNs TileSchedule::nextTime() const { return *std::min_element(due_.begin(), due_.end()); }

void TileSchedule::dueTiles(TimeNs t_ns, std::vector<int>* tiles) const {
  tiles->clear();
  for (int k = 0; k < tileCount(); ++k)
    if (due_[static_cast<std::size_t>(k)] <= t_ns) tiles->push_back(k);
}

cv::Rect TileSchedule::tileRect(int tile) const {
  const int x0 = (tile % tiles_x_) * tile_px_, y0 = (tile / tiles_x_) * tile_px_;
  return cv::Rect(x0, y0, std::min(tile_px_, width_ - x0), std::min(tile_px_, height_ - y0));
}

}  // namespace evio::simulator

#include "evio/simulator/tile_schedule.h"

#include <algorithm>
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
      log_eps_(static_cast<float>(log_eps)),
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
  const int x0 = r.x, y0 = r.y, x1 = r.x + r.width, y1 = r.y + r.height;
  for (int y = y0; y < y1; ++y) {
    const float* in = radiance.ptr<float>(y);
    float* l = log_.ptr<float>(y);
    for (int x = x0; x < x1; ++x) l[x] = std::log(log_eps_ + (in[x] > 0.0f ? in[x] : 0.0f));  // as logImage
  }
}

float TileSchedule::tileRate(int tile, const cv::Mat& flow) const {
  const cv::Rect r = tileRect(tile);
  float rate = 0.0f;
  if (!sampler_.options().rate_bound) {
    for (int y = r.y; y < r.y + r.height; ++y)
      for (int x = r.x; x < r.x + r.width; ++x) rate = std::max(rate, sampler_.logRateAt(log_, flow, x, y));
    return rate;
  }
  // AdaptiveSampler::logRateAt with rate_bound, the same float operations in
  // the same order, on row pointers: max over the 8 neighbours q of
  // |L(q) − L(p)| / ‖q − p‖, times 1 / cos 22.5° · ‖u̇v‖; non-finite counts as 0.
  // Pixels away from the image border: all 8 neighbours exist, no branches
  // (the maximum does not depend on the order of its terms).
  const int xa = std::max(r.x, 1), xb = std::min(r.x + r.width, width_ - 1);
  const auto interior = [&](int y) {
    const float* up = log_.ptr<float>(y - 1);
    const float* mid = log_.ptr<float>(y);
    const float* down = log_.ptr<float>(y + 1);
    const cv::Vec2f* f = flow.ptr<cv::Vec2f>(y);
    constexpr float kDiag = 0.70710678f;
    for (int x = xa; x < xb; ++x) {
      const float l = mid[x];
      float slope = 0.0f;
      const auto take = [&slope](float d) { slope = d > slope ? d : slope; };  // NaN never wins
      take(std::abs(up[x - 1] - l) * kDiag);
      take(std::abs(up[x] - l) * 1.0f);
      take(std::abs(up[x + 1] - l) * kDiag);
      take(std::abs(mid[x - 1] - l) * 1.0f);
      take(std::abs(mid[x + 1] - l) * 1.0f);
      take(std::abs(down[x - 1] - l) * kDiag);
      take(std::abs(down[x] - l) * 1.0f);
      take(std::abs(down[x + 1] - l) * kDiag);
      const float v = slope * 1.0823922f * std::sqrt(f[x][0] * f[x][0] + f[x][1] * f[x][1]);
      if (std::isfinite(v)) rate = std::max(rate, v);
    }
  };
  // Pixels on the image border: the neighbours that exist.
  const auto border = [&](int x, int y) {
    const float l = log_.at<float>(y, x);
    float slope = 0.0f;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int qx = x + dx, qy = y + dy;
        if ((dx == 0 && dy == 0) || qx < 0 || qy < 0 || qx >= width_ || qy >= height_) continue;
        const float d = std::abs(log_.at<float>(qy, qx) - l) * (dx != 0 && dy != 0 ? 0.70710678f : 1.0f);
        if (d > slope) slope = d;  // NaN never wins
      }
    const cv::Vec2f f = flow.at<cv::Vec2f>(y, x);
    const float v = slope * 1.0823922f * std::sqrt(f[0] * f[0] + f[1] * f[1]);
    if (std::isfinite(v)) rate = std::max(rate, v);
  };
  for (int y = r.y; y < r.y + r.height; ++y) {
    if (y == 0 || y + 1 == height_) {
      for (int x = r.x; x < r.x + r.width; ++x) border(x, y);
      continue;
    }
    interior(y);
    for (int x = r.x; x < xa; ++x) border(x, y);
    for (int x = std::max(xb, r.x); x < r.x + r.width; ++x) border(x, y);
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

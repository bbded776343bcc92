#include "evio/simulator/tile_schedule.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "evio/core/error.h"

namespace evio::simulator {

namespace {
AdaptiveSampler::Options perPixel(AdaptiveSampler::Options o) {
  o.tile_px = 1;  // the tile reduction happens here
  return o;
}
}  // namespace

TileSchedule::TileSchedule(int width, int height, int tile_px, const AdaptiveSampler::Options& sampler,
                           double threshold, double log_eps, TimeNs origin_ns, TimeNs quantum_ns)
    : width_(width),
      height_(height),
      tile_px_(tile_px),
      sampler_(perPixel(sampler), threshold, log_eps),
      log_eps_(static_cast<float>(log_eps)),
      origin_ns_(origin_ns),
      quantum_ns_(quantum_ns) {
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

void TileSchedule::reschedule(int tile, TimeNs t_ns, const cv::Mat& flow) {
  const cv::Rect r = tileRect(tile);
  const int x0 = r.x, y0 = r.y, x1 = r.x + r.width, y1 = r.y + r.height;
  float rate = 0.0f;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) rate = std::max(rate, sampler_.logRateAt(log_, flow, x, y));
  due_[static_cast<std::size_t>(tile)] = onGrid(t_ns, sampler_.interval(rate));
}

void TileSchedule::scheduleAll(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_,
          "TileSchedule: radiance must be CV_32FC1 of the schedule's size");
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "TileSchedule: flow must be CV_32FC2 of the radiance's size");
  // All logs first: a tile's rate reads its neighbours' new samples.
  for (int k = 0; k < tileCount(); ++k) updateLog(k, radiance);
  for (int k = 0; k < tileCount(); ++k) reschedule(k, t_ns, flow);
}

void TileSchedule::scheduleTiles(TimeNs t_ns, const std::vector<int>& tiles, const cv::Mat& radiance,
                                 const cv::Mat& flow) {
  require(radiance.type() == CV_32FC1 && radiance.rows == height_ && radiance.cols == width_,
          "TileSchedule: radiance must be CV_32FC1 of the schedule's size");
  require(flow.type() == CV_32FC2 && flow.size() == radiance.size(),
          "TileSchedule: flow must be CV_32FC2 of the radiance's size");
  for (const int k : tiles)
    if (k < 0 || k >= tileCount()) throw Error("TileSchedule: tile " + std::to_string(k) + " out of range");
  for (const int k : tiles) updateLog(k, radiance);
  for (const int k : tiles) reschedule(k, t_ns, flow);
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

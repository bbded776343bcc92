#pragma once
/// @file tile_schedule.h
/// When to re-render each tile of the image: the AdaptiveSampler rule
/// (adaptive_sampler.h) applied per tile, for a render loop that re-traces
/// only the tiles that are due (Renderer::renderTiles) and feeds their
/// pixels to EventCamera::updatePixels.
///
/// After tile k is sampled at t, its next sample is due after
///     Δt_k = clamp(λ C / max_{p ∈ k} Ṙ(p), 1 / max_rate_hz, 1 / min_rate_hz),
/// Ṙ(p) the sampler's predicted log-rate of pixel p from the latest log
/// image (each pixel's last sample: neighbours in other tiles may be older)
/// and the motion field at the tile's sample. So the fastest pixel of each
/// tile sets that tile's rate: tiles where the image is still or smooth are
/// re-traced rarely, tiles crossed by fast texture or edges often.
///
/// Due times lie on a grid origin + j·quantum (rounded down onto it, and at
/// least the grid point after t), so tiles fall due together: a render loop
/// makes at most one step per grid period instead of one per tile. With
/// quantum = 0 there is no grid (due = t + Δt).

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "evio/core/time.h"
#include "evio/simulator/adaptive_sampler.h"

namespace evio::simulator {

class TileSchedule {
 public:
  /// An image of width × height px in square tiles of tile_px (the last
  /// column and row narrower), numbered row-major as Renderer's tiles of the
  /// same size. `sampler` gives λ, the rate bounds and the rate predictor
  /// (its tile_px is not used); `threshold` and `log_eps` as AdaptiveSampler.
  /// `threads`: 0 = all cores, as the renderer (the schedule does not depend on it).
  TileSchedule(int width, int height, int tile_px, const AdaptiveSampler::Options& sampler, double threshold,
               double log_eps, TimeNs origin_ns, TimeNs quantum_ns, int threads = 1);

  /// Every tile sampled at t_ns: radiance (CV_32FC1, W/(m²·sr)) and motion
  /// field (CV_32FC2, px/s) of the whole image; reschedules every tile.
  void scheduleAll(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow);

  /// The tiles `tiles` sampled at t_ns: their pixels of radiance and flow
  /// are the new samples (other pixels are not read except as neighbours of
  /// the log image kept from earlier samples); reschedules those tiles.
  void scheduleTiles(TimeNs t_ns, const std::vector<int>& tiles, const cv::Mat& radiance, const cv::Mat& flow);

  /// The earliest due time over all tiles.
  TimeNs nextTime() const;
  /// The tiles due at or before t_ns, ascending, into *tiles (cleared first).
  void dueTiles(TimeNs t_ns, std::vector<int>* tiles) const;
  /// The pixels of tile k: [x0, x1) × [y0, y1) (Renderer::tileRect for the same tile_px).
  cv::Rect tileRect(int tile) const;

  int tileCount() const { return tiles_x_ * tiles_y_; }
  TimeNs due(int tile) const { return due_[static_cast<std::size_t>(tile)]; }
  /// The grid time at or before t + Δt, and after t.
  TimeNs onGrid(TimeNs t_ns, TimeNs interval_ns) const;

 private:
  void updateLog(int tile, const cv::Mat& radiance);
  void reschedule(int tile, TimeNs t_ns, const cv::Mat& flow);
  /// The largest predicted log-rate Ṙ over the pixels of the tile (AdaptiveSampler::logRateAt, same bits).
  float tileRate(int tile, const cv::Mat& flow) const;
  /// f(k) for k in [0, count), in parallel (each call touches its own tile only).
  template <class F>
  void forTiles(std::size_t count, const F& f) const;

  int width_ = 0, height_ = 0, tile_px_ = 1, tiles_x_ = 0, tiles_y_ = 0;
  AdaptiveSampler sampler_;
  TimeNs origin_ns_ = 0, quantum_ns_ = 0;
  int threads_ = 1;
  cv::Mat log_;               ///< L = log(ε + I) at each pixel's last sample (CV_32FC1)
  std::vector<TimeNs> due_;   ///< next sample time per tile
};

}  // namespace evio::simulator

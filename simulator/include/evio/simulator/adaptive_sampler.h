#pragma once
/// @file adaptive_sampler.h
/// When to sample (render) each pixel again so that the event camera's
/// linear interpolation between samples stays accurate (ESIM's adaptive
/// sampling, Rebecq et al. CoRL 2018, made per pixel).
///
/// For a static scene seen by a moving camera, brightness constancy gives
/// the rate of change of a pixel's log radiance L = log(ε + I):
///     dL/dt = −∇L · u̇v         (∇L in 1/px, u̇v the motion field in px/s),
/// so the next sample of a pixel is due after
///     Δt = clamp(λ C / Ṙ, 1 / max_rate_hz, 1 / min_rate_hz),
/// when its L is predicted to have changed by λ C (C the smaller contrast
/// threshold, λ = 0.5 by default), with the predicted rate Ṙ either
///   - rate_bound = true (default): Ṙ = g / cos 22.5° · ‖u̇v‖, g = max over
///     the 8 neighbours q of |L(q) − L(p)| / ‖q − p‖ (g / cos 22.5° ≥ ‖∇L‖
///     when L is linear over the neighbourhood): a bound that holds for any
///     flow direction and does not vanish at extrema of L, where ∇L = 0 but
///     the texture moving past still changes L;
///   - rate_bound = false: Ṙ = |∇L · u̇v| (ESIM's first-order prediction), ∇L
///     by central differences (one-sided at the border).
/// ESIM's whole-frame rule takes the smallest Δt over the image for every
/// pixel (wholeFrameInterval); the per-pixel rule re-samples only the pixels
/// that need it. NaN flow or radiance counts as no change. With tile_px > 1
/// every pixel of a tile gets the tile's smallest Δt (a renderer can then
/// re-trace whole tiles).
///
/// In a render loop: after rendering the pixels due at t (and feeding them to
/// EventCamera::updatePixel), call schedulePixel (or schedule for a whole
/// image) for them with the latest radiance image and motion field; the
/// next step is the earliest due time, also bounded by the caller's other
/// clocks (IMU samples, frame exposures). The accuracy kept against
/// whole-frame sampling at a fine step is measured in
/// tests/simulator/adaptive_sampling_test.cpp.

#include <opencv2/core/mat.hpp>
#include <vector>

#include "evio/core/options.h"
#include "evio/core/time.h"

namespace evio::simulator {

class AdaptiveSampler {
 public:
  struct Options {
    double lambda = 0.5;          ///< λ: fraction of the threshold L may change between samples
    double min_rate_hz = 30.0;    ///< every pixel is sampled at least this often, Hz
    double max_rate_hz = 1e5;     ///< no pixel is sampled more often than this, Hz
    int tile_px = 1;              ///< 1 = per pixel; n > 1 = per n × n tile
    bool rate_bound = true;       ///< Ṙ = max neighbour slope · ‖u̇v‖ (true) or |∇L · u̇v| (false)

    template <class V>
    void fields(V& v) {
      v("lambda", lambda, "fraction of the contrast threshold between samples");
      v("min_rate_hz", min_rate_hz, "minimum sample rate, Hz");
      v("max_rate_hz", max_rate_hz, "maximum sample rate, Hz");
      v("tile_px", tile_px, "1 = per pixel, n = per n x n tile");
      v("rate_bound", rate_bound, "predict with max neighbour slope * |flow| (else |grad L . flow|)");
    }
    void validate() const;
  };

  /// `threshold` is C (log units, the smaller of C⁺ and C⁻); `log_eps` the
  /// ε of the event camera's L = log(ε + I), W/(m²·sr).
  AdaptiveSampler(const Options& options, double threshold, double log_eps);

  /// L = log(ε + max(I, 0)) of a CV_32FC1 radiance image (CV_32FC1).
  cv::Mat logImage(const cv::Mat& radiance) const;

  /// The predicted rate Ṙ (1/s) at pixel (x, y) of a log image and a CV_32FC2 motion field.
  float logRateAt(const cv::Mat& log_image, const cv::Mat& flow, int x, int y) const;

  /// logImage of the pixels [x0, x1) of row y only, into *log_image (CV_32FC1
  /// of the radiance's size).
  void logRow(const cv::Mat& radiance, int y, int x0, int x1, cv::Mat* log_image) const;

  /// logRateAt(log_image, flow, x, y) for x in [x0, x1) into rates[0 .. x1 − x0),
  /// the same bits, on row pointers and without bounds tests for the pixels
  /// away from the image border (the renderer's every step).
  void logRatesOfRow(const cv::Mat& log_image, const cv::Mat& flow, int y, int x0, int x1, float* rates) const;

  /// The k-th smallest of *values (0-based, k < size; NaN not allowed), the
  /// value std::nth_element puts at k, by a radix pass over the top bits of
  /// the floats and a selection among the few in the k-th's bin. *values is
  /// the caller's scratch: its order changes.
  static float kthSmallest(std::vector<float>* values, std::size_t k);

  /// The sample interval for a predicted |dL/dt| (1/s), ns, within the rate bounds.
  TimeNs interval(float log_rate) const;

  /// Next sample time of pixel (x, y) sampled at t_ns.
  TimeNs schedulePixel(TimeNs t_ns, const cv::Mat& log_image, const cv::Mat& flow, int x, int y) const {
    return t_ns + interval(logRateAt(log_image, flow, x, y));
  }

  /// Next sample time of every pixel (row-major, resized to width·height)
  /// after a whole image sampled at t_ns; per tile when tile_px > 1.
  void schedule(TimeNs t_ns, const cv::Mat& radiance, const cv::Mat& flow, std::vector<TimeNs>* next_ns) const;

  /// ESIM's whole-frame interval: λ C / max |∇L · u̇v| within the rate bounds.
  TimeNs wholeFrameInterval(const cv::Mat& radiance, const cv::Mat& flow) const;

  const Options& options() const { return options_; }

 private:
  Options options_;
  double threshold_ = 0.0;
  float log_eps_ = 0.0f;
  TimeNs min_interval_ns_ = 0, max_interval_ns_ = 0;
  bool avx2_ = false;  ///< logRatesOfRow's interior eight pixels at a time (same bits)
};

}  // namespace evio::simulator

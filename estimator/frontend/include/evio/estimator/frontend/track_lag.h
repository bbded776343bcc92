#pragma once
/// @file track_lag.h
/// Online estimate of an event tracker's lag from the frames
/// (docs/algorithms.md#tracker-lag).
///
/// An event track point trails the feature along its motion by
///   lag = a + τ |v|    (a px in distance, τ s in time, v the image velocity),
/// measured against the simulator's truth for EKLT on the DAVIS240C
/// (docs/consistency.md "Tracker lag"): τ from the photoreceptor's low-pass,
/// a from how events trail a moving edge. Both depend on the sensor and the
/// light, so they are estimated here from the frames, whose positions do not
/// lag: every live event-tracked feature is also followed from frame to frame
/// by pyramidal Lucas–Kanade (its "frame position", started where the tracker
/// seeded the feature on a frame); at each frame t_k the event track,
/// extrapolated from its last two points to t_k as the synchroniser does,
/// is compared with the frame position s_k:
///   lag_k = −(û_k − s_k)·v̂,   v = (s_k − s_{k−1}) / (t_k − t_{k−1}),
/// and (a, τ) is the least-squares fit of lag_k = a + τ|v_k| over the
/// samples of the last memory_s seconds (exponential forgetting), with a
/// prior of one sample at a = τ = 0 so that a constant speed, which cannot
/// separate a from τ, still gives the lag at that speed.

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include <opencv2/core.hpp>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"
#include "evio/core/time.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

struct TrackLagOptions {
  /// Estimate the lag online and compensate it in the synchroniser (EKLT and
  /// HASTE; KLT does not lag). On: EKLT-VIO's error 1.5–4× lower and its
  /// ANEES near its bounds on the indoor analogues, unchanged in Mars
  /// daylight (docs/consistency.md "Tracker lag").
  bool estimate = true;
  double memory_s = 5.0;         ///< forgetting time constant of the fit, s
  double min_speed_pxps = 20.0;  ///< slower samples (direction ill-defined) are skipped, px/s
  double max_error_px = 3.0;     ///< samples farther off (a lost track or frame position) are skipped, px
  int min_samples = 30;          ///< effective samples before the estimate is used
  double max_point_age_s = 0.02; ///< an event track whose last point is older at the frame is skipped, s
  int window_px = 21;            ///< Lucas–Kanade window, px
  int pyramid_levels = 3;

  template <class V>
  void fields(V& v) {
    v("estimate", estimate, "estimate the event tracker's lag from the frames and compensate it");
    v("memory_s", memory_s, "forgetting time constant of the lag fit, s");
    v("min_speed_pxps", min_speed_pxps, "slower samples are skipped, px/s");
    v("max_error_px", max_error_px, "samples farther off are skipped, px");
    v("min_samples", min_samples, "effective samples before the estimate is used");
    v("max_point_age_s", max_point_age_s, "event tracks whose last point is older are skipped, s");
    v("window_px", window_px, "Lucas-Kanade window, px");
    v("pyramid_levels", pyramid_levels, "Lucas-Kanade pyramid levels");
  }
  void validate() const;
};

/// The lag model a + τ|v|.
struct TrackLag {
  double a_px = 0.0;
  double tau_s = 0.0;
};

/// Least squares of lag = a + τ s with exponential forgetting and a prior of
/// weight 1 at (0, 0) (τ scaled by kSpeedScale so both weigh alike).
class TrackLagFit {
 public:
  static constexpr double kSpeedScale = 100.0;  ///< px/s: the prior's unit speed
  /// Scales the accumulated samples by `factor` (in (0, 1]).
  void forget(double factor);
  void add(double speed_pxps, double lag_px);
  double effectiveSamples() const { return n_; }
  TrackLag solve() const;

 private:
  double n_ = 0.0, s1_ = 0.0, s2_ = 0.0, r1_ = 0.0, r2_ = 0.0;  // Σ1, Σs, Σs², Σlag, Σs·lag
};

/// Frame positions of the event-tracked features and the fit they feed.
class FrameLagProbe {
 public:
  explicit FrameLagProbe(const TrackLagOptions& options);

  /// Track points as the tracker emitted them (time order per feature).
  void observe(const TrackPoints& points, std::size_t begin);
  /// A sensor frame (CV_8UC1): moves every frame position to it, adds the
  /// samples, and remembers the frame.
  void addFrame(TimeNs t_ns, const cv::Mat& image);
  /// The current estimate, once min_samples effective samples are in.
  std::optional<TrackLag> lag() const;
  double effectiveSamples() const { return fit_.effectiveSamples(); }

 private:
  struct Feature {
    TimeNs t[2] = {0, 0};  ///< the last two event points (t[1] newest)
    Vec2 uv[2];
    int n = 0;
    bool has_frame_position = false;
    Vec2 frame_position = Vec2::Zero();  ///< at the previous frame
  };
  /// The event track extrapolated to t (nullopt when too old or too short).
  std::optional<Vec2> eventPosition(const Feature& f, TimeNs t_ns) const;
  void sample(const Feature& f, const Vec2& s_prev, const Vec2& s, TimeNs t_ns, double dt);

  TrackLagOptions options_;
  TrackLagFit fit_;
  std::unordered_map<FeatureId, Feature> features_;
  std::vector<FeatureId> order_;  ///< ids in first-seen order (deterministic iteration)
  cv::Mat previous_;
  TimeNs previous_t_ns_ = 0;
  bool have_previous_ = false;
};

}  // namespace evio::estimator

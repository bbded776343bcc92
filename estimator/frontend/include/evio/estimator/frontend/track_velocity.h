#pragma once
/// @file track_velocity.h
/// The image velocity of one feature track from its recent points, for the
/// lag compensation (synchronizer.h): a point is moved forward along the
/// velocity by the tracker's lag a + τ|v| and to the set's time.
///
/// With a window W > 0 the velocity is the least-squares slope of the
/// track's points in the last W seconds (t_k, uv_k), k = 1..n:
///   v = Σ (t_k − t̄)(uv_k − ūv) / Σ (t_k − t̄)²,  px/s,
/// always over at least the newest two points. With W = 0 it is the slope
/// of the newest two points alone. EKLT's points lie a few ms and a fraction
/// of a pixel apart, each about 0.5 px off, so the two-point slope carries
/// hundreds of px/s of noise into every compensated point
/// (docs/consistency.md "The velocity that moves a point by its lag").

#include <deque>
#include <optional>
#include <utility>

#include "evio/core/eigen_types.h"
#include "evio/core/time.h"

namespace evio::estimator {

/// A track's point uv moved along its velocity v (px/s) by dt seconds and a
/// further `distance_px` along v/|v|: uv + dt v + distance v/|v| (a still
/// track, v = 0: uv). The synchroniser's extrapolation and lag compensation
/// (synchronizer.h) and `evio track --lag-compensated` both move points so.
Vec2 moveAlongVelocity(const Vec2& uv, const Vec2& velocity, double dt_s, double distance_px);

class TrackVelocity {
 public:
  /// `window_s` >= 0: the span of points the slope is fitted over, s.
  explicit TrackVelocity(double window_s = 0.0);

  /// A new point; a point at the newest time replaces it, an older one is ignored.
  void add(TimeNs t_ns, const Vec2& uv);
  /// px/s; nullopt with fewer than two points.
  std::optional<Vec2> velocity() const;
  std::size_t size() const { return points_.size(); }

 private:
  TimeNs window_ns_;
  std::deque<std::pair<TimeNs, Vec2>> points_;  // oldest first; memory bounded by the window
};

}  // namespace evio::estimator

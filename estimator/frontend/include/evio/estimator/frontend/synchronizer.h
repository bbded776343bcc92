#pragma once
/// @file synchronizer.h
/// Asynchronous feature tracks → synchronous measurement sets for the filter
/// (Mahlknecht et al. 2022, Frontend Adaptations; docs/algorithms.md#synchronisation).
///
/// Triggers:
///  - "events": every n_e events in total, if any track moved since the last
///    update. The update time is the latest timestamp among the live tracks
///    and must be strictly after the previous update (else no update).
///  - "fixed_rate": every 1/rate_hz seconds of data time.
///  - "track_time": whenever the latest track timestamp advances (e.g. KLT,
///    whose points all carry frame times: one update per frame).
/// With track_latency_s = τ > 0 the extrapolation goes to t_s + τ instead:
/// the latency of the tracker compensated along each track's velocity; with
/// track_lag_px = a > 0 the position is moved a further a px along the
/// track's direction (a lag in distance, independent of the speed).
/// Each feature of a set is flagged informative (measurements.h) unless
/// drop_repeated_points and it has no new track point since the previous
/// update, or it moved less than min_displacement_px since its last
/// informative position.
/// Independently, min_rate_hz > 0 forces an update when no update happened
/// for 1/min_rate_hz seconds of data time (scenes without events).
/// At an update every live track is linearly extrapolated to the update time
/// from its last two points, or along the velocity fitted over its last
/// velocity_window_s (held when it has one point; at most
/// max_extrapolation_s beyond its last point), and carries the position it
/// was sent with at the previous update and the covariance and error time
/// constant its tracker stated for its newest point. The tracker's lag
/// (track_latency_s τ, track_lag_px a: moved a px further along the motion
/// and extrapolated τ later) is compensated only when that newest point came
/// from events: a point measured on a frame (TrackPoint::measured_on_frame,
/// EKLT's detection and bootstrap) does not lag. The velocity that moves the
/// first event points is still taken over points with and without the lag
/// until the bootstrap leaves it: on a line at speed |v| its slope is off by
/// about (a + τ|v|) / (t1 − t0), t1 − t0 the time the fitted points span
/// (velocity_window_s = 0: the gap from the bootstrap to the first event
/// point, a few ms, so the first event point's extrapolation, and its τ|v|,
/// can be well off).

#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <vector>

#include "evio/core/options.h"
#include "evio/estimator/frontend/track_velocity.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

struct SynchronizerOptions {
  std::string trigger = "events";     ///< events | fixed_rate | track_time
  int n_e = 3200;                     ///< events per update ("events")
  double rate_hz = 30.0;              ///< update rate ("fixed_rate")
  double min_rate_hz = 0.0;           ///< minimum update rate (0: off)
  double max_extrapolation_s = 0.1;   ///< extrapolation horizon beyond a track's last point
  /// Mark a feature not informative (measurements.h) when its tracker gave no
  /// new point since the previous update: the extrapolated repeat of an
  /// old point carries no new information. On by default: lower error for
  /// EKLT-VIO and HASTE-VIO on the calibrated sensors (docs/consistency.md
  /// "EKLT on real-like events", campaign eklt_variants); KLT-VIO gives one
  /// point per feature per set and is unaffected.
  bool drop_repeated_points = true;
  /// Mark a feature not informative until its position has moved this far
  /// from its last informative position, px (0: any motion).
  double min_displacement_px = 0.0;
  /// The tracker's latency τ, s: a track point stamped t shows where the
  /// feature was at t − τ, so a track is sent at the set time t_s as its
  /// extrapolation to t_s + τ (from its last two points, the track's
  /// velocity). 0: the points are taken as stamped.
  double track_latency_s = 0.0;
  /// The tracker's lag in distance, px: a track point lies this far behind
  /// the feature along the track's direction of motion (from its last two
  /// points), whatever the speed; each sent position is moved forward by it.
  /// With track_latency_s = τ the lag of a point is a + τ |v|. 0: none.
  double track_lag_px = 0.0;
  /// The velocity that moves a point forward (by the lag and to the set's
  /// time), s: fitted over the track's points of the last this many seconds
  /// (track_velocity.h), always its newest two at least. 0: the slope of its
  /// newest two points alone.
  double velocity_window_s = 0.0;

  template <class V>
  void fields(V& v) {
    v("trigger", trigger, "events, fixed_rate or track_time");
    v("n_e", n_e, "events per update");
    v("rate_hz", rate_hz, "update rate for fixed_rate, Hz");
    v("min_rate_hz", min_rate_hz, "minimum update rate, Hz (0: off)");
    v("max_extrapolation_s", max_extrapolation_s, "extrapolation horizon, s");
    v("drop_repeated_points", drop_repeated_points, "features without a new track point are not informative");
    v("min_displacement_px", min_displacement_px, "motion since the last informative position, px");
    v("track_latency_s", track_latency_s, "tracker latency compensated along the track's velocity, s");
    v("track_lag_px", track_lag_px, "tracker lag along the track's direction compensated, px");
    v("velocity_window_s", velocity_window_s, "the track velocity is fitted over its points of this last span, s (0: last two)");
  }
  void validate() const;
};

/// A track's position at t, extrapolated along the line through its last
/// two points (t0, uv0) and (t1, uv1), t0 < t1: uv1 + (t − t1)/(t1 − t0)·(uv1 − uv0).
/// The synchroniser sends tracks this way; the lag probe (track_lag.h)
/// compares the same extrapolation with the frames.
inline Vec2 extrapolateLinearly(TimeNs t0, const Vec2& uv0, TimeNs t1, const Vec2& uv1, TimeNs t) {
  const double s = static_cast<double>(t - t1) / static_cast<double>(t1 - t0);
  return uv1 + s * (uv1 - uv0);
}

class Synchronizer {
 public:
  /// Replaces the compensated lag (track_latency_s, track_lag_px) from the
  /// next set on: the frontend's online estimate (track_lag.h). Negative
  /// parts are taken as 0.
  void setTrackLag(double a_px, double tau_s);
  explicit Synchronizer(const SynchronizerOptions& options);

  /// Track points in the order the tracker produced them.
  void addTrackPoints(const TrackPoints& points);
  /// `count` more events were processed; the newest has time t_last_ns.
  void addEvents(std::uint64_t count, TimeNs t_last_ns);
  /// Data time has reached t_ns (IMU, frames): fixed and minimum rates.
  void advanceTime(TimeNs t_ns);

  /// Pops the oldest pending measurement set; false when none.
  bool poll(MeasurementSet* out);

  std::size_t numLiveTracks() const { return tracks_.size(); }

 private:
  struct Track {
    TimeNs t[2] = {0, 0};   // last two points, t[1] newest
    Vec2 uv[2] = {Vec2::Zero(), Vec2::Zero()};
    Mat2 cov = Mat2::Zero();  // of the newest point, px² (zero: not stated)
    bool newest_on_frame = false;  // the newest point was measured on a frame: no lag
    double error_time_s = 0.0;  // of the newest point (TrackPoint::error_time_s)
    bool informed = false;    // an informative position was sent
    Vec2 last_informative = Vec2::Zero();
    int n = 0;
    bool moved = true;
    bool sent = false;
    Vec2 last_sent = Vec2::Zero();
    TrackVelocity velocity;   // fitted over velocity_window_s (kept only when it is > 0)
  };
  enum class Trigger { kEvents, kFixedRate, kTrackTime };
  /// The track at t_ns, its newest point moved lag_px further along the motion.
  Vec2 extrapolate(const Track& track, TimeNs t_ns, double lag_px) const;
  void update(TimeNs t_ns);
  TimeNs latestTrackTime() const;

  SynchronizerOptions options_;
  Trigger trigger_;
  std::unordered_map<FeatureId, Track> tracks_;
  std::vector<FeatureId> order_;  // ids in creation order, for deterministic output
  std::deque<MeasurementSet> pending_;
  std::uint64_t events_since_update_ = 0;
  bool any_update_ = false;
  TimeNs last_update_ns_ = 0;
  TimeNs last_time_ns_ = 0;
  bool any_time_ = false;
  TimeNs next_fixed_ns_ = -1;
  TimeNs latest_point_ns_ = 0;
  TimeNs latency_ns_ = 0;  // track_latency_s (or setTrackLag)
  double lag_px_ = 0.0;    // track_lag_px (or setTrackLag)
};

}  // namespace evio::estimator

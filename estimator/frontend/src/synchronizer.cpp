#include "evio/estimator/frontend/synchronizer.h"

#include <algorithm>
#include <limits>

#include "evio/core/error.h"

namespace evio::estimator {

void SynchronizerOptions::validate() const {
  requireField(trigger == "events" || trigger == "fixed_rate" || trigger == "track_time", "trigger",
               "must be events, fixed_rate or track_time (got '" + trigger + "')");
  requireField(n_e >= 1, "n_e", "must be >= 1");
  requirePositive("rate_hz", rate_hz);
  requireInRange("rate_hz", rate_hz, 0.0, 1e5);  // updates per second
  requireInRange("min_rate_hz", min_rate_hz, 0.0, 1e5);
  requireNonNegative("max_extrapolation_s", max_extrapolation_s);
  requireInRange("min_displacement_px", min_displacement_px, 0.0, 100.0);
  requireInRange("track_latency_s", track_latency_s, 0.0, 0.05);
  requireInRange("track_lag_px", track_lag_px, 0.0, 10.0);
  requireInRange("velocity_window_s", velocity_window_s, 0.0, 1.0);
}

Synchronizer::Synchronizer(const SynchronizerOptions& options) : options_(options) {
  options_.validate();
  latency_ns_ = secondsToNs(options_.track_latency_s);
  lag_px_ = options_.track_lag_px;
  trigger_ = options_.trigger == "events"       ? Trigger::kEvents
             : options_.trigger == "fixed_rate" ? Trigger::kFixedRate
                                                : Trigger::kTrackTime;
}

void Synchronizer::addTrackPoints(const TrackPoints& points) {
  TimeNs newest = std::numeric_limits<TimeNs>::min();
  for (const TrackPoint& p : points) {
    if (p.status == TrackStatus::kLost) {
      if (tracks_.erase(p.feature_id) > 0) std::erase(order_, p.feature_id);
      continue;
    }
    auto [it, inserted] = tracks_.try_emplace(p.feature_id);
    if (inserted) {
      order_.push_back(p.feature_id);
      it->second.velocity = TrackVelocity(options_.velocity_window_s);
    }
    Track& tr = it->second;
    if (options_.velocity_window_s > 0.0) tr.velocity.add(p.t_ns, p.uv);
    if (tr.n > 0 && p.t_ns <= tr.t[1]) {  // same time: replace the newest point; older: ignore
      if (p.t_ns == tr.t[1]) {
        tr.uv[1] = p.uv;
        tr.cov = p.cov_px;
        tr.error_time_s = p.error_time_s;
        tr.newest_on_frame = p.measured_on_frame;
        tr.moved = true;
      }
      continue;
    }
    tr.t[0] = tr.t[1];
    tr.uv[0] = tr.uv[1];
    tr.t[1] = p.t_ns;
    tr.uv[1] = p.uv;
    tr.cov = p.cov_px;
    tr.error_time_s = p.error_time_s;
    tr.newest_on_frame = p.measured_on_frame;
    tr.n = std::min(tr.n + 1, 2);
    tr.moved = true;
    newest = std::max(newest, p.t_ns);
  }
  if (trigger_ == Trigger::kTrackTime && newest != std::numeric_limits<TimeNs>::min()) {
    const TimeNs t = latestTrackTime();
    if (!any_update_ || t > last_update_ns_) update(t);
  }
}

TimeNs Synchronizer::latestTrackTime() const {
  TimeNs t = std::numeric_limits<TimeNs>::min();
  for (const auto& [id, tr] : tracks_) t = std::max(t, tr.t[1]);
  return t;
}

void Synchronizer::addEvents(std::uint64_t count, TimeNs t_last_ns) {
  if (trigger_ == Trigger::kEvents) {
    events_since_update_ += count;
    if (events_since_update_ >= static_cast<std::uint64_t>(options_.n_e)) {
      events_since_update_ = 0;
      const bool moved = std::any_of(tracks_.begin(), tracks_.end(), [](const auto& kv) { return kv.second.moved; });
      if (moved && !tracks_.empty()) {
        const TimeNs t = latestTrackTime();
        if (!any_update_ || t > last_update_ns_) update(t);
      }
    }
  }
  advanceTime(t_last_ns);
}

void Synchronizer::advanceTime(TimeNs t_ns) {
  if (any_time_ && t_ns < last_time_ns_) return;  // late stamps do not move time back
  last_time_ns_ = t_ns;
  any_time_ = true;
  if (trigger_ == Trigger::kFixedRate) {
    const TimeNs period = secondsToNs(1.0 / options_.rate_hz);
    if (next_fixed_ns_ < 0) next_fixed_ns_ = t_ns + period;
    while (next_fixed_ns_ <= t_ns) {
      if (!tracks_.empty()) update(next_fixed_ns_);
      next_fixed_ns_ += period;
    }
  }
  if (options_.min_rate_hz > 0.0 && !tracks_.empty()) {
    const TimeNs max_gap = secondsToNs(1.0 / options_.min_rate_hz);
    if (!any_update_) {
      any_update_ = true;  // start the clock at the first time seen with tracks
      last_update_ns_ = t_ns;
    } else if (t_ns - last_update_ns_ >= max_gap) {
      update(t_ns);
    }
  }
}

void Synchronizer::setTrackLag(double a_px, double tau_s) {
  lag_px_ = std::max(0.0, a_px);
  latency_ns_ = secondsToNs(std::max(0.0, tau_s));
}

Vec2 Synchronizer::extrapolate(const Track& tr, TimeNs t_ns, double lag_px) const {
  if (tr.n < 2 || tr.t[1] == tr.t[0]) return tr.uv[1];
  const TimeNs horizon = secondsToNs(options_.max_extrapolation_s);
  const TimeNs t = std::min(t_ns, tr.t[1] + horizon);
  if (options_.velocity_window_s > 0.0) {
    // uv1 + v (t − t1) + a v/|v|: the newest point moved along the fitted velocity.
    if (const auto v = tr.velocity.velocity()) return moveAlongVelocity(tr.uv[1], *v, nsToSeconds(t - tr.t[1]), lag_px);
  }
  const Vec2 step = tr.uv[1] - tr.uv[0];
  const double length = step.norm();
  // The lag in distance, a px along the direction of the last step.
  const Vec2 lag = length > 0.0 ? Vec2(lag_px / length * step) : Vec2::Zero();
  return extrapolateLinearly(tr.t[0], tr.uv[0], tr.t[1], tr.uv[1], t) + lag;
}

void Synchronizer::update(TimeNs t_ns) {
  MeasurementSet set;
  set.t_ns = t_ns;
  set.features.reserve(order_.size());
  for (FeatureId id : order_) {
    Track& tr = tracks_.at(id);
    FeatureMeasurement m;
    m.id = id;
    // A point measured on a frame does not lag: no latency, no lag distance.
    m.uv = tr.newest_on_frame ? extrapolate(tr, t_ns, 0.0) : extrapolate(tr, t_ns + latency_ns_, lag_px_);
    m.cov_px = tr.cov;
    m.error_time_s = tr.error_time_s;
    m.informative = (!options_.drop_repeated_points || tr.moved) &&
                    (!tr.informed || (m.uv - tr.last_informative).norm() >= options_.min_displacement_px);
    if (m.informative) {
      tr.informed = true;
      tr.last_informative = m.uv;
    }
    m.has_previous = tr.sent;
    m.uv_previous = tr.sent ? tr.last_sent : m.uv;
    tr.last_sent = m.uv;
    tr.sent = true;
    tr.moved = false;
    set.features.push_back(m);
  }
  any_update_ = true;
  last_update_ns_ = t_ns;
  pending_.push_back(std::move(set));
}

bool Synchronizer::poll(MeasurementSet* out) {
  if (pending_.empty()) return false;
  *out = std::move(pending_.front());
  pending_.pop_front();
  return true;
}

}  // namespace evio::estimator

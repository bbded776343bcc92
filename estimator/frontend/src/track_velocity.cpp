#include "evio/estimator/frontend/track_velocity.h"

#include "evio/core/options.h"

namespace evio::estimator {

Vec2 moveAlongVelocity(const Vec2& uv, const Vec2& velocity, double dt_s, double distance_px) {
  const double speed = velocity.norm();
  if (!(speed > 0.0)) return uv;
  return uv + dt_s * velocity + (distance_px / speed) * velocity;
}

TrackVelocity::TrackVelocity(double window_s) : window_ns_(secondsToNs(window_s)) {
  requireInRange("velocity_window_s", window_s, 0.0, 1.0);
}

void TrackVelocity::add(TimeNs t_ns, const Vec2& uv) {
  if (!points_.empty() && t_ns <= points_.back().first) {
    if (t_ns == points_.back().first) points_.back().second = uv;
    return;
  }
  points_.emplace_back(t_ns, uv);
  // Keep the newest two and every point within the window of the newest.
  while (points_.size() > 2 && points_.front().first < t_ns - window_ns_) points_.pop_front();
}

std::optional<Vec2> TrackVelocity::velocity() const {
  if (points_.size() < 2) return std::nullopt;
  // Times relative to the newest point, s (small numbers: no cancellation).
  const TimeNs t_ref = points_.back().first;
  double t_mean = 0.0;
  Vec2 uv_mean = Vec2::Zero();
  for (const auto& [t, uv] : points_) {
    t_mean += nsToSeconds(t - t_ref);
    uv_mean += uv;
  }
  const double n = static_cast<double>(points_.size());
  t_mean /= n;
  uv_mean /= n;
  double stt = 0.0;
  Vec2 stu = Vec2::Zero();
  for (const auto& [t, uv] : points_) {
    const double dt = nsToSeconds(t - t_ref) - t_mean;
    stt += dt * dt;
    stu += dt * (uv - uv_mean);
  }
  if (!(stt > 0.0)) return std::nullopt;
  return Vec2(stu / stt);
}

}  // namespace evio::estimator

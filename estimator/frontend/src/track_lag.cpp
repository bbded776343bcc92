#include "evio/estimator/frontend/track_lag.h"

#include <algorithm>
#include <cmath>

#include <opencv2/video/tracking.hpp>

#include "evio/core/error.h"
#include "evio/estimator/frontend/synchronizer.h"

namespace evio::estimator {

void TrackLagOptions::validate() const {
  requireInRange("memory_s", memory_s, 0.01, 3600.0);
  requireInRange("min_speed_pxps", min_speed_pxps, 0.0, 1e5);
  requireInRange("max_error_px", max_error_px, 0.01, 100.0);
  requireField(min_samples >= 1 && min_samples <= 1000000, "min_samples", "must be in [1, 1000000]");
  requireInRange("max_point_age_s", max_point_age_s, 1e-4, 1.0);
  requireField(window_px >= 5 && window_px <= 101 && window_px % 2 == 1, "window_px", "must be odd, in [5, 101]");
  requireField(pyramid_levels >= 1 && pyramid_levels <= 8, "pyramid_levels", "must be in [1, 8]");
}

// --- TrackLagFit ---------------------------------------------------------------------

void TrackLagFit::forget(double factor) {
  n_ *= factor;
  s1_ *= factor;
  s2_ *= factor;
  r1_ *= factor;
  r2_ *= factor;
}

void TrackLagFit::add(double speed_pxps, double lag_px) {
  n_ += 1.0;
  s1_ += speed_pxps;
  s2_ += speed_pxps * speed_pxps;
  r1_ += lag_px;
  r2_ += speed_pxps * lag_px;
}

TrackLag TrackLagFit::solve() const {
  // Normal equations of Σ (lag − a − τ s)² + a² + (τ kSpeedScale)²:
  //   [n + 1, Σs; Σs, Σs² + S²] [a; τ] = [Σlag; Σs·lag],
  // with a ≥ 0 and τ ≥ 0 (a lag, not a lead): when the free solution has a
  // negative part, that part is 0 and the other is fitted alone.
  const double m00 = n_ + 1.0, m01 = s1_, m11 = s2_ + kSpeedScale * kSpeedScale;
  const double det = m00 * m11 - m01 * m01;
  TrackLag out;
  if (!(det > 0.0)) return out;
  out.a_px = (m11 * r1_ - m01 * r2_) / det;
  out.tau_s = (m00 * r2_ - m01 * r1_) / det;
  if (out.a_px >= 0.0 && out.tau_s >= 0.0) return out;
  const TrackLag distance_only{std::max(0.0, r1_ / m00), 0.0};
  const TrackLag time_only{0.0, std::max(0.0, r2_ / m11)};
  // The better of the two one-parameter fits (the smaller residual sum).
  const auto cost = [&](const TrackLag& x) {
    return m00 * x.a_px * x.a_px + 2.0 * m01 * x.a_px * x.tau_s + m11 * x.tau_s * x.tau_s -
           2.0 * (x.a_px * r1_ + x.tau_s * r2_);
  };
  return cost(distance_only) <= cost(time_only) ? distance_only : time_only;
}

// --- FrameLagProbe -------------------------------------------------------------------

FrameLagProbe::FrameLagProbe(const TrackLagOptions& options) : options_(options) { options_.validate(); }

void FrameLagProbe::observe(const TrackPoints& points, std::size_t begin) {
  for (std::size_t k = begin; k < points.size(); ++k) {
    const TrackPoint& p = points[k];
    if (p.status == TrackStatus::kLost) {
      features_.erase(p.feature_id);
      continue;
    }
    auto [it, inserted] = features_.try_emplace(p.feature_id);
    if (inserted) order_.push_back(p.feature_id);
    Feature& f = it->second;
    // A point stamped at the last frame is the tracker's seed on that frame:
    // the frame position starts there.
    if (!f.has_frame_position && have_previous_ && p.t_ns == previous_t_ns_) {
      f.has_frame_position = true;
      f.frame_position = p.uv;
    }
    // The event track is made of event points alone: a point measured on a
    // frame (the detection, the bootstrap) does not lag, and a line through
    // it and a lagged point would not move at the track's speed.
    if (p.measured_on_frame) continue;
    if (f.n > 0 && p.t_ns <= f.t[1]) {  // two points at one time: keep the newest
      if (p.t_ns == f.t[1]) f.uv[1] = p.uv;
      continue;
    }
    f.t[0] = f.t[1];
    f.uv[0] = f.uv[1];
    f.t[1] = p.t_ns;
    f.uv[1] = p.uv;
    f.n = std::min(f.n + 1, 2);
  }
}

std::optional<Vec2> FrameLagProbe::eventPosition(const Feature& f, TimeNs t_ns) const {
  if (f.n < 2 || f.t[1] <= f.t[0] || f.t[1] > t_ns) return std::nullopt;
  if (nsToSeconds(t_ns - f.t[1]) > options_.max_point_age_s) return std::nullopt;
  return extrapolateLinearly(f.t[0], f.uv[0], f.t[1], f.uv[1], t_ns);
}

void FrameLagProbe::sample(const Feature& f, const Vec2& s_prev, const Vec2& s, TimeNs t_ns, double dt) {
  const std::optional<Vec2> u = eventPosition(f, t_ns);
  if (!u) return;
  const Vec2 v = (s - s_prev) / dt;
  const double speed = v.norm();
  const Vec2 error = *u - s;
  if (!(speed >= options_.min_speed_pxps) || !(error.norm() <= options_.max_error_px)) return;
  fit_.add(speed, -error.dot(v) / speed);
}

void FrameLagProbe::addFrame(TimeNs t_ns, const cv::Mat& image) {
  if (have_previous_ && t_ns > previous_t_ns_) {
    const double dt = nsToSeconds(t_ns - previous_t_ns_);
    fit_.forget(std::exp(-dt / options_.memory_s));
    std::vector<FeatureId> ids;
    std::vector<cv::Point2f> p0, p1;
    for (const FeatureId id : order_) {
      const auto it = features_.find(id);
      if (it == features_.end() || !it->second.has_frame_position) continue;
      const Vec2& s = it->second.frame_position;
      ids.push_back(id);
      p0.emplace_back(static_cast<float>(s.x()), static_cast<float>(s.y()));
    }
    if (!p0.empty()) {
      std::vector<std::uint8_t> status;
      std::vector<float> err;
      cv::calcOpticalFlowPyrLK(previous_, image, p0, p1, status, err, cv::Size(options_.window_px, options_.window_px),
                               options_.pyramid_levels - 1,
                               cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 30, 0.01));
      for (std::size_t k = 0; k < ids.size(); ++k) {
        Feature& f = features_.at(ids[k]);
        const Vec2 s(p1[k].x, p1[k].y);
        const bool inside = s.x() >= 0.0 && s.y() >= 0.0 && s.x() < image.cols - 1 && s.y() < image.rows - 1;
        if (status[k] == 0 || !inside || !s.allFinite()) {
          f.has_frame_position = false;
          continue;
        }
        sample(f, f.frame_position, s, t_ns, dt);
        f.frame_position = s;
      }
    }
  }
  // Forget features no longer tracked (ids lost without a kLost point stay
  // until the tracker reports them; the order list is compacted here).
  std::vector<FeatureId> alive;
  alive.reserve(order_.size());
  for (const FeatureId id : order_)
    if (features_.count(id) != 0) alive.push_back(id);
  order_.swap(alive);
  image.copyTo(previous_);
  previous_t_ns_ = t_ns;
  have_previous_ = true;
}

std::optional<TrackLag> FrameLagProbe::lag() const {
  if (fit_.effectiveSamples() < options_.min_samples) return std::nullopt;
  return fit_.solve();
}

}  // namespace evio::estimator

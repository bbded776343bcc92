#include "evio/estimator/frontend/gyro_predictor.h"

#include <algorithm>

#include "evio/core/error.h"
#include "evio/core/so3.h"

namespace evio::estimator {

GyroPredictor::GyroPredictor(Camera camera, const Pose& T_B_C, double history_s)
    : camera_(std::move(camera)), R_B_C_(T_B_C.rotation()), history_ns_(secondsToNs(history_s)) {
  require(history_s > 0.0, "GyroPredictor: history_s must be > 0");
}

void GyroPredictor::addImu(const ImuSample& sample) {
  require(samples_.empty() || sample.t_ns > samples_.back().t_ns,
          "GyroPredictor: IMU time must increase");
  samples_.push_back(sample);
  while (samples_.size() > 2 && samples_.front().t_ns < sample.t_ns - history_ns_) samples_.pop_front();
}

Vec3 GyroPredictor::gyroAt(TimeNs t) const {
  if (t <= samples_.front().t_ns) return samples_.front().gyro_B;
  if (t >= samples_.back().t_ns) return samples_.back().gyro_B;
  const auto it = std::lower_bound(samples_.begin(), samples_.end(), t,
                                   [](const ImuSample& s, TimeNs v) { return s.t_ns < v; });
  const ImuSample& b = *it;
  const ImuSample& a = *(it - 1);
  const double w = static_cast<double>(t - a.t_ns) / static_cast<double>(b.t_ns - a.t_ns);
  return (1.0 - w) * a.gyro_B + w * b.gyro_B;
}

Mat3 GyroPredictor::integrate(TimeNs t0, TimeNs t1) const {
  Mat3 R = Mat3::Identity();
  TimeNs t = t0;
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t0,
                             [](TimeNs v, const ImuSample& s) { return v < s.t_ns; });
  while (t < t1) {
    const TimeNs next = (it != samples_.end() && it->t_ns < t1) ? it->t_ns : t1;
    const TimeNs mid = t + (next - t) / 2;
    R = R * so3::exp(gyroAt(mid) * nsToSeconds(next - t));
    t = next;
    if (it != samples_.end() && it->t_ns <= t) ++it;
  }
  return R;
}

Mat3 GyroPredictor::rotation(TimeNs t0, TimeNs t1) const {
  if (samples_.empty() || t0 == t1) return Mat3::Identity();
  return t0 < t1 ? integrate(t0, t1) : integrate(t1, t0).transpose();
}

std::optional<Vec2> GyroPredictor::predict(const Vec2& uv0, TimeNs t0, TimeNs t1) const {
  Vec3 f0;
  if (!camera_.unproject(uv0, &f0)) return std::nullopt;
  const Mat3 R_C0_C1 = R_B_C_.transpose() * rotation(t0, t1) * R_B_C_;
  const Vec3 f1 = R_C0_C1.transpose() * f0;
  Vec2 uv1;
  if (!camera_.project(f1, &uv1)) return std::nullopt;
  return uv1;
}

}  // namespace evio::estimator

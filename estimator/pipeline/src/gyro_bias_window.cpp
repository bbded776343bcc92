#include "evio/estimator/pipeline/gyro_bias_window.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include "evio/core/error.h"

namespace evio::estimator {

GyroBiasWindow::GyroBiasWindow(double window_s, double keyframe_s, const Camera& camera, const Mat3& R_B_C,
                               TimeNs time_offset_cam_imu_ns, const WindowRestTest& rest_test,
                               const GyroBiasFromTracksOptions& solver)
    : window_s_(window_s),
      keyframe_s_(keyframe_s),
      camera_(camera),
      R_B_C_(R_B_C),
      offset_ns_(time_offset_cam_imu_ns),
      rest_test_(rest_test),
      solver_(solver) {}

void GyroBiasWindow::open(const ImuState& x0) {
  x0_ = x0;
  complete_ = false;
  next_keyframe_ns_ = x0.t_ns;
}

bool GyroBiasWindow::add(BackendInput in) {
  if (const auto* imu = std::get_if<ImuSample>(&in)) {
    imu_.push_back(*imu);
    if (nsToSeconds(imu->t_ns - x0_->t_ns) >= window_s_) complete_ = true;
  } else if (const auto* set = std::get_if<MeasurementSet>(&in)) {
    const TimeNs t_imu = set->t_ns + offset_ns_;
    if (nsToSeconds(t_imu - x0_->t_ns) > window_s_) {
      complete_ = true;  // the data passed the window's end without an IMU reading
    } else if (t_imu >= next_keyframe_ns_) {
      addKeyframe(*set, t_imu);
      while (next_keyframe_ns_ <= t_imu) next_keyframe_ns_ += secondsToNs(keyframe_s_);
    }
  } else if (nsToSeconds(std::get<RangeMeasurement>(in).t_ns + offset_ns_ - x0_->t_ns) > window_s_) {
    complete_ = true;
  }
  inputs_.push_back(std::move(in));
  return complete_;
}

void GyroBiasWindow::addKeyframe(const MeasurementSet& set, TimeNs t_imu_ns) {
  BearingKeyframe kf;
  kf.t_imu_ns = t_imu_ns;
  for (const FeatureMeasurement& f : set.features) {
    Vec3 bearing;
    // A feature that is not informative repeats an earlier position (no new
    // track point): it does not show where the feature is at this time.
    if (f.informative && camera_.unproject(f.uv, &bearing)) kf.bearings_C.emplace_back(f.id, bearing.normalized());
  }
  std::sort(kf.bearings_C.begin(), kf.bearings_C.end(),
            [](const auto& a, const auto& b) { return a.first < b.first; });
  keyframes_.push_back(std::move(kf));
}

GyroBiasEstimate GyroBiasWindow::estimate(const Mat3& prior_covariance) {
  complete_ = true;
  // Only keyframes the readings cover can be integrated between (x0 may lie
  // up to one IMU period before the first reading the window holds).
  const TimeNs t_first = imu_.empty() ? x0_->t_ns : imu_.front().t_ns;
  const TimeNs t_last = imu_.empty() ? x0_->t_ns : imu_.back().t_ns;
  keyframes_.erase(std::remove_if(keyframes_.begin(), keyframes_.end(),
                                  [&](const BearingKeyframe& k) { return k.t_imu_ns < t_first || k.t_imu_ns > t_last; }),
                   keyframes_.end());
  if (rest_test_.enabled)
    rest_ = restMeasurement(imu_, rest_test_.gravity_mps2, rest_test_.max_acc_std_mps2,
                            rest_test_.max_gyro_std_radps, rest_test_.noise);
  GyroBiasEstimate e;
  if (rest_) {
    e.b_g = x0_->b_g;
    e.covariance = prior_covariance;
    e.at_rest = true;
    e.rest_s = rest_->durationS();
  } else {
    e = estimateGyroBiasFromTracks(keyframes_, imu_, R_B_C_, x0_->b_g, prior_covariance, solver_);
  }
  imu_ = ImuSamples();
  keyframes_ = std::vector<BearingKeyframe>();
  return e;
}

}  // namespace evio::estimator

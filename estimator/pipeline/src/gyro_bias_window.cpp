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

GyroBiasEstimate GyroBiasWindow::estimate(const Eigen::Matrix<double, 15, 15>& P0) {
  complete_ = true;
  const Mat3 prior_covariance = P0.block<3, 3>(kIdxBg, kIdxBg);
  GyroBiasEstimate e;
  if (rest_test_.enabled) {
    const std::optional<RestMeasurement> rest = restMeasurement(
        imu_, rest_test_.gravity_mps2, rest_test_.max_acc_std_mps2, rest_test_.max_gyro_std_radps, rest_test_.noise);
    ImuState x = *x0_;
    Eigen::Matrix<double, 15, 15> P = P0;
    if (rest && applyRestMeasurement(*rest, rest_test_.gravity_mps2, &x, &P)) {
      x.t_ns = rest->t1_ns;  // at rest nothing moved: the same state at the window's end
      e.b_g = x.b_g;
      e.covariance = P.block<3, 3>(kIdxBg, kIdxBg);
      e.at_rest = true;
      e.rest_s = rest->durationS();
      e.rest_b_a = x.b_a;
      e.rest_b_a_covariance = P.block<3, 3>(kIdxBa, kIdxBa);
      rest_start_.emplace(x, P);
    }
  }
  if (!e.at_rest) {
    // Only keyframes the readings cover can be integrated between (x0 may lie
    // up to one IMU period before the first reading the window holds).
    const TimeNs t_first = imu_.empty() ? x0_->t_ns : imu_.front().t_ns;
    const TimeNs t_last = imu_.empty() ? x0_->t_ns : imu_.back().t_ns;
    keyframes_.erase(std::remove_if(keyframes_.begin(), keyframes_.end(),
                                    [&](const BearingKeyframe& k) { return k.t_imu_ns < t_first || k.t_imu_ns > t_last; }),
                     keyframes_.end());
    e = estimateGyroBiasFromTracks(keyframes_, imu_, R_B_C_, x0_->b_g, prior_covariance, solver_);
  }
  imu_ = ImuSamples();
  keyframes_ = std::vector<BearingKeyframe>();
  return e;
}

std::vector<BackendInput> GyroBiasWindow::takeInputsFrom(TimeNs t_imu_ns) {
  std::vector<BackendInput> out;
  for (BackendInput& in : inputs_) {
    TimeNs t_imu = 0;
    if (const auto* imu = std::get_if<ImuSample>(&in)) t_imu = imu->t_ns;
    else if (const auto* set = std::get_if<MeasurementSet>(&in)) t_imu = set->t_ns + offset_ns_;
    else t_imu = std::get<RangeMeasurement>(in).t_ns + offset_ns_;
    if (t_imu >= t_imu_ns) out.push_back(std::move(in));
  }
  inputs_.clear();
  return out;
}

}  // namespace evio::estimator

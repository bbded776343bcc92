#include "evio/estimator/pipeline/gyro_bias_window.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Eigenvalues>

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
  if (const auto* corners = std::get_if<FrameCorners>(&in)) {
    // Evidence only: kept as bearings, not buffered for the filter.
    if (stillTestOn()) addStillCorners(*corners);
    return complete_;
  }
  if (const auto* imu = std::get_if<ImuSample>(&in)) {
    imu_.push_back(*imu);
    if (nsToSeconds(imu->t_ns - x0_->t_ns) >= window_s_) complete_ = true;
  } else if (const auto* set = std::get_if<MeasurementSet>(&in)) {
    const TimeNs t_imu = set->t_ns + offset_ns_;
    if (nsToSeconds(t_imu - x0_->t_ns) > window_s_) {
      complete_ = true;  // the data passed the window's end without an IMU reading
    } else {
      if (stillTestOn()) addStillObservations(*set, t_imu);
      if (t_imu >= next_keyframe_ns_) {
        addKeyframe(*set, t_imu);
        while (next_keyframe_ns_ <= t_imu) next_keyframe_ns_ += secondsToNs(keyframe_s_);
      }
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

void GyroBiasWindow::addStillObservations(const MeasurementSet& set, TimeNs t_imu_ns) {
  for (const FeatureMeasurement& f : set.features) {
    Vec3 bearing;
    if (f.informative && camera_.unproject(f.uv, &bearing))
      still_observations_.push_back(BearingObservation{t_imu_ns, f.id, bearing.normalized()});
  }
}

void GyroBiasWindow::addStillCorners(const FrameCorners& corners) {
  const TimeNs t_imu = corners.t_ns + offset_ns_;
  for (const auto& [index, uv] : corners.corners_px) {
    Vec3 bearing;
    // Negative ids: apart from the tracker's features.
    if (camera_.unproject(uv, &bearing))
      still_observations_.push_back(BearingObservation{t_imu, -1 - index, bearing.normalized()});
  }
}

GyroBiasWindow::ImageVerdict GyroBiasWindow::imagesStill(TimeNs t1_ns, double* missed_variance,
                                                         GyroBiasEstimate* e) const {
  // The stated noise of still tracks (WindowRestTest::still_track_sigma_px)
  // as an angle at the focal length.
  const double sigma_rad = rest_test_.still_track_sigma_px / camera_.intrinsics()(0);
  const TimeNs t0 = imu_.empty() ? x0_->t_ns : std::min(x0_->t_ns, imu_.front().t_ns);
  const std::optional<ImageRotationRate> rate = imageRotationRate(still_observations_, t0, t1_ns, sigma_rad);
  if (!rate) return ImageVerdict::kCannotTell;
  e->rest_image_features = rate->features;
  e->rest_image_chi2 = rate->chi2();
  constexpr double kChi2Gate = 16.27;  // χ²₃ at 0.999
  if (!(e->rest_image_chi2 <= kChi2Gate)) return ImageVerdict::kMoving;
  // A steady turn the gate lets through is up to about √16.27 σ along the
  // covariance's longest axis: carried as a uniform error on ±√16.27 σ.
  const double largest = Eigen::SelfAdjointEigenSolver<Mat3>(rate->covariance).eigenvalues().maxCoeff();
  *missed_variance = kChi2Gate * largest / 3.0;
  return ImageVerdict::kStill;
}

void GyroBiasWindow::tryStillRest(const Eigen::Matrix<double, 15, 15>& P0, GyroBiasEstimate* e) {
  // Still until it moves: the block test decides where the rest ends (the
  // window's end, or a prefix at least prefix.min_s long).
  const std::optional<StillPrefix> prefix = stillPrefix(imu_, rest_test_.noise, rest_test_.prefix);
  if (!prefix) return;
  const ImuSamples still = prefix->every_block
                               ? imu_
                               : ImuSamples(imu_.begin(), imu_.begin() + static_cast<std::ptrdiff_t>(prefix->readings));
  std::optional<RestMeasurement> rest = restMeasurement(still, rest_test_.gravity_mps2, rest_test_.max_acc_std_mps2,
                                                        rest_test_.max_gyro_std_radps, rest_test_.noise);
  if (!rest) return;
  // Where the images cannot tell (fewer than five corners or features seen
  // twice: a helicopter on textureless ground, a run without frames), a
  // whole still window is taken for rest on the IMU's word, as before; a
  // prefix is not: it ends where the IMU saw motion begin, and a steady turn
  // just before it passes every IMU test (5 of 100 prefixes of KLT-VIO runs
  // that move from their first reading did).
  double image_missed_variance = 0.0;
  const ImageVerdict images = imagesStill(rest->t1_ns, &image_missed_variance, e);
  if (images == ImageVerdict::kMoving || (images == ImageVerdict::kCannotTell && !prefix->every_block)) return;
  if (!prefix->every_block) {
    // A prefix ends where motion began: its last blocks may hold the onset
    // below the thresholds, which the allowances carry. A whole window
    // showed no onset at all, and keeps the white noise alone (with the
    // allowances mars_flight's runs lost accuracy: EKLT-VIO 0.40 -> 0.71 %,
    // HASTE-VIO 10 -> 6 of 10 held).
    rest->gyro_variance += prefix->gyro_allowance_variance + image_missed_variance;
    rest->acc_variance += prefix->acc_allowance_variance;
  }
  applyRest(*rest, P0, e);
  e->rest_prefix = e->at_rest && !prefix->every_block;
}

GyroBiasEstimate GyroBiasWindow::estimate(const Eigen::Matrix<double, 15, 15>& P0) {
  complete_ = true;
  const Mat3 prior_covariance = P0.block<3, 3>(kIdxBg, kIdxBg);
  GyroBiasEstimate e;
  if (stillTestOn()) {
    tryStillRest(P0, &e);
  } else if (rest_test_.enabled) {
    // The spread test alone on the whole window.
    if (const std::optional<RestMeasurement> rest = restMeasurement(
            imu_, rest_test_.gravity_mps2, rest_test_.max_acc_std_mps2, rest_test_.max_gyro_std_radps, rest_test_.noise))
      applyRest(*rest, P0, &e);
  }
  if (!e.at_rest) {
    // Only keyframes the readings cover can be integrated between (x0 may lie
    // up to one IMU period before the first reading the window holds).
    const TimeNs t_first = imu_.empty() ? x0_->t_ns : imu_.front().t_ns;
    const TimeNs t_last = imu_.empty() ? x0_->t_ns : imu_.back().t_ns;
    keyframes_.erase(std::remove_if(keyframes_.begin(), keyframes_.end(),
                                    [&](const BearingKeyframe& k) { return k.t_imu_ns < t_first || k.t_imu_ns > t_last; }),
                     keyframes_.end());
    const int image_features = e.rest_image_features;  // the images' still test, kept for the summary
    const double image_chi2 = e.rest_image_chi2;
    e = estimateGyroBiasFromTracks(keyframes_, imu_, R_B_C_, x0_->b_g, prior_covariance, solver_);
    e.rest_image_features = image_features;
    e.rest_image_chi2 = image_chi2;
  }
  imu_ = ImuSamples();
  keyframes_ = std::vector<BearingKeyframe>();
  still_observations_ = std::vector<BearingObservation>();
  return e;
}

void GyroBiasWindow::applyRest(const RestMeasurement& rest, const Eigen::Matrix<double, 15, 15>& P0,
                               GyroBiasEstimate* e) {
  ImuState x = *x0_;
  Eigen::Matrix<double, 15, 15> P = P0;
  if (!applyRestMeasurement(rest, rest_test_.gravity_mps2, &x, &P)) return;
  x.t_ns = rest.t1_ns;  // at rest nothing moved: the same state at the rest's end
  e->b_g = x.b_g;
  e->covariance = P.block<3, 3>(kIdxBg, kIdxBg);
  e->at_rest = true;
  e->rest_s = rest.durationS();
  e->rest_b_a = x.b_a;
  e->rest_b_a_covariance = P.block<3, 3>(kIdxBa, kIdxBa);
  rest_start_.emplace(x, P);
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

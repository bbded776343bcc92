#include "evio/estimator/backend/backend.h"

#include <Eigen/Cholesky>
#include <cmath>
#include <string>

#include "evio/core/error.h"
#include "evio/core/so3.h"
#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/imu_propagation.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/static_initializer.h"
#include "evio/estimator/backend/visual_models.h"

namespace evio::estimator {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// σ_z in normalised image coordinates: σ_img_px / mean focal length (px),
/// unless given directly.
double normalizedImageSigma(const BackendOptions& options, const Camera& camera) {
  const Vec4 k = camera.intrinsics();
  return options.sigma_img_normalized > 0.0 ? options.sigma_img_normalized
                                            : options.sigma_img_px / (0.5 * (k(0) + k(1)));
}
}  // namespace

Backend::Backend(const BackendOptions& options, const BackendSensors& sensors)
    : options_(options),
      sensors_(sensors),
      sigma_z_(normalizedImageSigma(options, sensors.camera)),
      slam_chi2_(options.slam_gate_probability),
      msckf_chi2_(options.msckf_gate_probability),
      triangulated_(static_cast<std::size_t>(std::max(options.map_prior_memory, 0))),
      range_(updaterContext(), sensors.range_finder.value_or(RangeFinderSensor{}), &msckf_chi2_),
      zero_velocity_(updaterContext()),
      msckf_(updaterContext(), sensors.camera, sigma_z_ * sigma_z_, &msckf_chi2_),
      slam_(updaterContext(), sensors.camera, sigma_z_, &slam_chi2_, &msckf_chi2_, &range_) {
  options_.validate();
  require(std::isfinite(sensors_.gravity_mps2) && sensors_.gravity_mps2 > 0.0, "backend: gravity must be > 0");
  if (options_.use_rig_imu_noise) sensors_.imu.validate();
  noise_ = options_.imuNoise(sensors_.imu);
  g_W_ = Vec3(0.0, 0.0, -sensors_.gravity_mps2);
}

// --- initialisation --------------------------------------------------------------------

void Backend::initialize(const ImuState& state) { initialize(state, initialCovariance()); }

Eigen::Matrix<double, 15, 15> Backend::initialCovariance() const {
  Eigen::Matrix<double, 15, 15> P0 = Eigen::Matrix<double, 15, 15>::Zero();
  auto var = [](double sigma) { return std::max(sigma * sigma, 1e-12); };
  P0.diagonal().segment<3>(kIdxP).setConstant(var(options_.initial_sigma_p_m));
  P0.diagonal().segment<3>(kIdxV).setConstant(var(options_.initial_sigma_v_mps));
  P0.diagonal().segment<3>(kIdxTheta).setConstant(var(options_.initial_sigma_theta_deg * kDeg));
  P0.diagonal().segment<3>(kIdxBg).setConstant(var(options_.initial_sigma_bg_degps * kDeg));
  P0.diagonal().segment<3>(kIdxBa).setConstant(var(options_.initial_sigma_ba_mps2));
  return P0;
}

Mat2 Backend::normalisedCovariance(double sigma_px) const {
  const Vec4 k = sensors_.camera.intrinsics();  // fx fy cx cy: normalised = px / f
  return Vec2(sigma_px * sigma_px / (k(0) * k(0)), sigma_px * sigma_px / (k(1) * k(1))).asDiagonal();
}

void Backend::initialize(const ImuState& state, const Eigen::Matrix<double, 15, 15>& P0) {
  require(state.p_W_B.allFinite() && state.v_W.allFinite() && state.q_W_B.coeffs().allFinite() &&
              state.b_g.allFinite() && state.b_a.allFinite(),
          "Backend::initialize: the initial state is not finite");
  require(P0.allFinite(), "Backend::initialize: the initial covariance is not finite");
  state_ = FilterState();
  if (options_.slam_track_error_sigma_px > 0.0) {
    state_.feature_dim = kFeatureDim + kTrackErrorDim;
    state_.track_error_cov = normalisedCovariance(options_.slam_track_error_sigma_px);
    state_.track_error_time_s = options_.slam_track_error_time_s;
  }
  state_.imu = state;
  state_.imu.q_W_B.normalize();
  state_.P = 0.5 * (P0 + P0.transpose());
  if (options_.slam_image_shift_sigma_px > 0.0)
    state_.addImageShift(normalisedCovariance(options_.slam_image_shift_sigma_px), options_.slam_image_shift_time_s);
  fej_imu_ = state_.imu;
  initialized_ = true;
  tracks_.clear();
  triangulated_ = TriangulatedPoints(static_cast<std::size_t>(std::max(options_.map_prior_memory, 0)));
  initialized_at_ = state_.imu.t_ns;
  last_full_covariance_test_ns_ = std::numeric_limits<TimeNs>::min();  // the first test after a start is full
  // The IMU reading at the initial time: interpolated between buffered
  // readings, else held from the nearest one.
  while (imu_buffer_.size() >= 2 && imu_buffer_[1].t_ns <= state.t_ns) imu_buffer_.pop_front();
  have_imu_at_state_ = false;
  if (!imu_buffer_.empty()) {
    if (imu_buffer_.front().t_ns <= state.t_ns) {
      imu_at_state_ = imu_buffer_.size() >= 2 ? interpolateImu(imu_buffer_[0], imu_buffer_[1], state.t_ns)
                                              : imu_buffer_.front();
      imu_buffer_.pop_front();
    } else {
      imu_at_state_ = imu_buffer_.front();
    }
    imu_at_state_.t_ns = state.t_ns;
    have_imu_at_state_ = true;
  }
  process();
}

bool Backend::staticInitialize(const ImuSamples& samples) {
  const auto result = estimator::staticInitialize(samples, sensors_.gravity_mps2, options_.static_max_acc_std_mps2,
                                                  options_.static_max_gyro_std_radps);
  if (!result) return false;
  initialize(result->state);
  return true;
}

void Backend::tryAutoStaticInit() {
  if (imu_buffer_.empty()) return;
  const TimeNs window = secondsToNs(options_.static_window_s);
  while (imu_buffer_.size() > 2 && imu_buffer_.back().t_ns - imu_buffer_[1].t_ns >= window) imu_buffer_.pop_front();
  if (imu_buffer_.back().t_ns - imu_buffer_.front().t_ns < window) return;
  const ImuSamples samples(imu_buffer_.begin(), imu_buffer_.end());
  staticInitialize(samples);
}

// --- input -------------------------------------------------------------------------------

void Backend::addImu(const ImuSample& in) {
  if (!status_.ok()) return;
  if (have_last_imu_) {
    if (in.t_ns < last_imu_.t_ns)
      throw Error("Backend::addImu: reading at " + secondsText(in.t_ns, 6) + " is older than the previous one at " +
                  secondsText(last_imu_.t_ns, 6));
    if (in.t_ns == last_imu_.t_ns) {
      ++stats_.imu_duplicates_dropped;
      return;
    }
  }
  ImuSample s = in;
  if (!s.acc_B.allFinite() || !s.gyro_B.allFinite() || s.acc_B.norm() > options_.imu_max_acc_mps2) {
    ++stats_.imu_outliers_replaced;
    if (!have_last_imu_) return;  // nothing to replace it with yet
    s.acc_B = last_imu_.acc_B;
    s.gyro_B = last_imu_.gyro_B;
  }
  if (have_last_imu_) {
    const double gap_s = nsToSeconds(s.t_ns - last_imu_.t_ns);
    if (gap_s > options_.imu_max_gap_s) ++stats_.imu_gaps;
    if (gap_s > options_.imu_fail_gap_s && initialized_) {
      setStatus(BackendStatus::Code::kFailed, "IMU gap of " + std::to_string(gap_s) + " s before " +
                                                  secondsText(s.t_ns, 6));
      return;
    }
  }
  ++stats_.imu_samples;
  last_imu_ = s;
  have_last_imu_ = true;
  imu_buffer_.push_back(s);
  if (!initialized_) {
    if (auto_static_init_) tryAutoStaticInit();
    else if (imu_buffer_.size() > 2) imu_buffer_.pop_front();  // keep a reading before a later initialize()
    return;
  }
  if (!have_imu_at_state_) {  // initialised before any IMU: hold the first reading back to the initial time
    imu_at_state_ = s;
    imu_at_state_.t_ns = state_.imu.t_ns;
    have_imu_at_state_ = s.t_ns >= state_.imu.t_ns;
    if (!have_imu_at_state_) imu_buffer_.pop_front();
  }
  process();
}

void Backend::enqueue(TimeNs t_imu_ns, Item item) {
  pending_.emplace(std::make_pair(t_imu_ns, next_seq_++), std::move(item));
  process();
}

namespace {
void requireOrdered(TimeNs* last, TimeNs t_ns, const char* what) {
  if (t_ns < *last)
    throw Error(std::string("Backend: ") + what + " at " + secondsText(t_ns, 6) + " is older than the previous one at " +
                secondsText(*last, 6));
  *last = t_ns;
}
}  // namespace

void Backend::addMeasurementSet(const MeasurementSet& set) {
  if (!status_.ok()) return;
  requireOrdered(&last_set_t_, set.t_ns, "measurement set");
  if (!initialized_) {
    ++stats_.measurements_before_init;
    return;
  }
  enqueue(set.t_ns + sensors_.time_offset_cam_imu_ns, set);
}

void Backend::addRange(TimeNs t_ns, double range_m) {
  if (!status_.ok() || !initialized_) return;
  require(sensors_.range_finder.has_value(), "Backend::addRange: the rig has no range finder");
  requireOrdered(&last_range_t_, t_ns, "range reading");
  enqueue(t_ns + sensors_.time_offset_cam_imu_ns, RangeItem{range_m});
}

void Backend::addZeroVelocity(TimeNs t_ns) {
  if (!status_.ok() || !initialized_) return;
  requireOrdered(&last_zero_velocity_t_, t_ns, "zero-velocity update");
  enqueue(t_ns + sensors_.time_offset_cam_imu_ns, ZeroVelocityItem{});
}

// --- processing ------------------------------------------------------------------------

void Backend::process() {
  if (!initialized_ || !have_imu_at_state_) return;
  const TimeNs newest = imu_buffer_.empty() ? imu_at_state_.t_ns : imu_buffer_.back().t_ns;
  while (status_.ok() && !pending_.empty() && pending_.begin()->first.first <= newest) {
    const TimeNs t_ns = pending_.begin()->first.first;
    // A range reading waits until max_delay_s of IMU lies beyond it: measurement
    // sets stamped earlier may still come (EKLT's sets lag the event stream),
    // and moving the state to the reading first would make them late.
    if (std::holds_alternative<RangeItem>(pending_.begin()->second) &&
        t_ns > newest - secondsToNs(options_.max_delay_s))
      break;
    Item item = std::move(pending_.begin()->second);
    pending_.erase(pending_.begin());
    processItem(t_ns, item);
  }
  if (!status_.ok()) return;
  const TimeNs advance_to = newest - secondsToNs(options_.max_delay_s);
  if (advance_to > state_.imu.t_ns && (pending_.empty() || pending_.begin()->first.first > advance_to)) {
    propagateTo(advance_to);
    checkHealth();
  }
}

void Backend::processItem(TimeNs t_ns, Item& item) {
  if (t_ns < state_.imu.t_ns) {
    if (nsToSeconds(state_.imu.t_ns - t_ns) > options_.max_late_s) {
      ++stats_.measurements_late_dropped;
      return;
    }
  } else {
    propagateTo(t_ns);
  }
  bool updated = true;
  if (auto* set = std::get_if<MeasurementSet>(&item)) processMeasurementSet(*set);
  else if (auto* range = std::get_if<RangeItem>(&item)) updated = range_.update(range->range_m);
  else updated = zero_velocity_.update();
  if (!updated) setStatus(BackendStatus::Code::kDiverged, "innovation covariance not positive definite");
  checkHealth();
}

void Backend::integrateStep(const ImuSample& s1, Mat15* Phi_acc, Mat15* Q_acc) {
  const ImuSample s0 = imu_at_state_;
  imu_at_state_ = s1;
  if (s1.t_ns <= s0.t_ns) return;
  const Mat3 R0 = state_.imu.q_W_B.toRotationMatrix();
  const Vec3 a0 = s0.acc_B - state_.imu.b_a;
  const double dt = nsToSeconds(s1.t_ns - s0.t_ns);
  Mat15 Phi;
  integrateImuStep(state_.imu, s0, s1, g_W_, &Phi);
  *Q_acc = Phi * *Q_acc * Phi.transpose() + discreteImuNoise(R0, a0, dt, noise_);
  *Phi_acc = Phi * *Phi_acc;
}

void Backend::propagateTo(TimeNs t_ns) {
  if (t_ns <= state_.imu.t_ns) return;
  const TimeNs t0 = state_.imu.t_ns;
  Mat15 Phi = Mat15::Identity(), Q = Mat15::Zero();
  while (!imu_buffer_.empty() && imu_buffer_.front().t_ns <= t_ns) {
    integrateStep(imu_buffer_.front(), &Phi, &Q);
    imu_buffer_.pop_front();
  }
  if (state_.imu.t_ns < t_ns) {
    const ImuSample s = imu_buffer_.empty() ? ImuSample{t_ns, imu_at_state_.acc_B, imu_at_state_.gyro_B}
                                            : interpolateImu(imu_at_state_, imu_buffer_.front(), t_ns);
    integrateStep(s, &Phi, &Q);
  }
  state_.imu.t_ns = t_ns;
  if (options_.observability_constraint) {
    // Over the whole interval the chained transition has, exactly (T = t − t0),
    //   Φ_θθ = R_tᵀ R_0,  Φ_vθ = −[v_t − v_0 − g T]x R_0,  Φ_pθ = −[p_t − p_0 − v_0 T − ½ g T²]x R_0;
    // first-estimate Jacobians evaluate them at the state before the updates at t0.
    const double T = nsToSeconds(t_ns - t0);
    const Mat3 R0 = fej_imu_.q_W_B.toRotationMatrix();
    const ImuState& x = state_.imu;
    Phi.block<3, 3>(kIdxTheta, kIdxTheta) = x.q_W_B.toRotationMatrix().transpose() * R0;
    Phi.block<3, 3>(kIdxV, kIdxTheta) = -so3::hat(x.v_W - fej_imu_.v_W - g_W_ * T) * R0;
    Phi.block<3, 3>(kIdxP, kIdxTheta) =
        -so3::hat(x.p_W_B - fej_imu_.p_W_B - fej_imu_.v_W * T - 0.5 * g_W_ * T * T) * R0;
  }
  fej_imu_ = state_.imu;
  // P_II ← Φ P_II Φᵀ + Q,  P_IX ← Φ P_IX (clones and features do not move).
  const Mat15 P_II = state_.P.topLeftCorner<15, 15>();
  const Mat15 P_new = Phi * P_II * Phi.transpose() + Q;
  state_.P.topLeftCorner<15, 15>() = 0.5 * (P_new + P_new.transpose());
  const int rest = state_.dim() - kImuDim;
  if (rest > 0) {
    const MatX P_IX = Phi * state_.P.topRightCorner(kImuDim, rest);
    state_.P.topRightCorner(kImuDim, rest) = P_IX;
    state_.P.bottomLeftCorner(rest, kImuDim) = P_IX.transpose();
  }
}

// --- health and output -----------------------------------------------------------------

void Backend::setStatus(BackendStatus::Code code, const std::string& cause) {
  if (!status_.ok()) return;
  status_.code = code;
  status_.t_ns = state_.imu.t_ns;
  status_.cause = cause;
}

void Backend::finish() {
  if (initialized_) checkHealth(true);
}

void Backend::checkHealth(bool full_test) {
  if (!status_.ok()) return;
  const ImuState& x = state_.imu;
  if (!x.p_W_B.allFinite() || !x.v_W.allFinite() || !x.q_W_B.coeffs().allFinite() || !x.b_g.allFinite() ||
      !x.b_a.allFinite())
    return setStatus(BackendStatus::Code::kDiverged, "non-finite IMU state");
  if (!state_.P.allFinite()) return setStatus(BackendStatus::Code::kDiverged, "non-finite covariance");
  if (x.v_W.norm() > options_.max_velocity_mps)
    return setStatus(BackendStatus::Code::kDiverged,
                     "velocity " + std::to_string(x.v_W.norm()) + " m/s above max_velocity_mps");
  if ((state_.P.diagonal().array() <= 0.0).any())
    return setStatus(BackendStatus::Code::kDiverged, "covariance with a non-positive variance");
  if (const auto pair = negativeMinor())
    return setStatus(BackendStatus::Code::kDiverged,
                     "covariance not positive semi-definite (variables " + std::to_string(pair->first) + " and " +
                         std::to_string(pair->second) + ")");
  const TimeNs interval_ns = secondsToNs(options_.covariance_check_interval_s);
  const bool due = last_full_covariance_test_ns_ == std::numeric_limits<TimeNs>::min() ||
                   x.t_ns - last_full_covariance_test_ns_ >= interval_ns;
  if (!full_test && !due) return;
  last_full_covariance_test_ns_ = x.t_ns;
  // Right after cloning P is only positive semi-definite (the clone is a
  // function of the IMU state), so the test is a Cholesky factorisation of
  // P + 1e-9 diag(P): it succeeds for every PSD P and fails once an eigenvalue
  // is negative beyond round-off.
  MatX Pr = state_.P;
  Pr.diagonal() *= 1.0 + 1e-9;
  const Eigen::LLT<MatX> llt(Pr);
  if (llt.info() != Eigen::Success)
    return setStatus(BackendStatus::Code::kDiverged, "covariance not positive semi-definite");
}

std::optional<std::pair<Eigen::Index, Eigen::Index>> Backend::negativeMinor() const {
  // A principal submatrix of a positive definite matrix is positive definite:
  // with D = (1 + 1e-9) diag(P), every P_ij² < D_i D_j when the Cholesky test
  // passes. The extra 1e-10 keeps this test strictly weaker than the
  // factorisation, whose own rounding is about n·2⁻⁵³ (1e-14 here).
  const MatX& P = state_.P;
  const VecX variance = P.diagonal();
  const double scale = (1.0 + 1e-9) * (1.0 + 1e-9) * (1.0 + 1e-10);
  for (Eigen::Index j = 0; j < P.cols(); ++j)
    for (Eigen::Index i = j + 1; i < P.rows(); ++i)
      if (P(i, j) * P(i, j) > scale * variance(i) * variance(j)) return std::make_pair(j, i);
  return std::nullopt;
}

Estimate Backend::makeEstimate() const {
  Estimate e;
  e.t_ns = state_.imu.t_ns;
  e.imu = state_.imu;
  e.T_W_B = state_.imu.T_W_B();
  e.T_W_C = e.T_W_B * sensors_.T_B_C;
  if (state_.P.rows() >= kImuDim) {
    e.cov_imu = state_.P.topLeftCorner<15, 15>();
    Eigen::Matrix<double, 6, 15> J = Eigen::Matrix<double, 6, 15>::Zero();
    J.block<3, 3>(0, kIdxP).setIdentity();
    J.block<3, 3>(3, kIdxTheta).setIdentity();
    e.cov_pose_B = J * e.cov_imu * J.transpose();
    Eigen::Matrix<double, 6, 15> Jc;
    cameraPose(state_.imu, sensors_.T_B_C, &Jc);
    e.cov_pose_C = Jc * e.cov_imu * Jc.transpose();
  }
  e.num_clones = static_cast<int>(state_.clones.size());
  e.num_slam_features = static_cast<int>(state_.features.size());
  e.num_msckf_features = msckf_.lastCount();
  e.innovation = innovation_;
  return e;
}

Estimate Backend::estimate() const { return makeEstimate(); }

std::vector<Estimate> Backend::takeEstimates() {
  std::vector<Estimate> out;
  out.swap(estimates_);
  return out;
}

}  // namespace evio::estimator

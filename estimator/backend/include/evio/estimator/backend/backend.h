#pragma once
/// @file backend.h
/// The xVIO-style EKF backend of EKLT-VIO and KLT-VIO (Mahlknecht et al. 2022,
/// Backend; docs/algorithms.md#ekf-backend). State and error-state convention:
/// filter_state.h; propagation: imu_propagation.h; updates: msckf_update.h,
/// slam_features.h, range_update.h, ekf_update.h.
///
/// Driving it: feed the IMU stream and the measurement streams, each in
/// non-decreasing time, interleaved in any order. A measurement is processed
/// once the IMU covers its time: the state is propagated to exactly that time
/// (the limit of "the buffered state nearest the measurement", with the IMU
/// reading interpolated between its neighbours), updated, and the buffered IMU
/// after it is re-propagated on the next measurement. Without measurements the
/// state follows the IMU at most max_delay_s behind.
///
/// Per measurement set (time t, camera clock; t_imu = t + time offset):
///   1. propagate to t and clone the camera pose into the window;
///   2. SLAM features observed in the set give 2 residuals each
///      (Mahalanobis-gated); SLAM features not observed are marginalised;
///   3. MSCKF features: tracks about to lose their oldest observation as the
///      window slides (and lost tracks when msckf_use_lost_tracks) whose
///      triangulation fixes the depth, null-space projected and χ²-gated;
///   4. one stacked, QR-compressed EKF update of 2 and 3;
///   5. free SLAM slots are filled with the longest live tracks of at least
///      slam_min_track_length observations: from triangulation when the
///      track fixes the inverse depth better than the depth prior
///      (triangulate_when_better_than_prior), else with the depth prior;
///   6. the previous newest pose is marginalised when it is not a keyframe
///      (closer than keyframe_interval_s to the pose before it), else the
///      oldest when the window exceeds M poses; SLAM features anchored on the
///      marginalised pose are re-anchored on the newest.
///
/// Divergence (non-finite state, covariance with a non-positive variance or not
/// positive semi-definite — cloning makes it singular by construction — velocity
/// above max_velocity_mps) and failure (an IMU gap above imu_fail_gap_s) set
/// status(); afterwards all input is ignored. Out-of-order input throws
/// evio::Error (bad input, not a filter state).

#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <optional>
#include <unordered_map>
#include <utility>
#include <variant>
#include <vector>

#include "evio/core/imu_sample.h"
#include "evio/estimator/backend/backend_options.h"
#include "evio/estimator/backend/backend_status.h"
#include "evio/estimator/backend/aux_updaters.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/feature_selection.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/backend/msckf_updater.h"
#include "evio/estimator/backend/slam_updater.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

class Backend {
 public:
  Backend(const BackendOptions& options, const BackendSensors& sensors);
  Backend(const Backend&) = delete;  // the updaters point into it
  Backend& operator=(const Backend&) = delete;

  // Initialisation ------------------------------------------------------------------
  /// From a given state (the paper's protocol: ground-truth pose and velocity,
  /// zero biases), state.t_ns on the IMU clock, with the initial covariance of
  /// the options.
  void initialize(const ImuState& state);
  /// The same with an explicit 15×15 initial covariance (filter_state.h order).
  void initialize(const ImuState& state, const Eigen::Matrix<double, 15, 15>& P0);
  /// The options' initial covariance: diagonal, from initial_sigma_*.
  Eigen::Matrix<double, 15, 15> initialCovariance() const;
  /// The filter time initialize() was given (IMU clock); 0 before.
  TimeNs initializedAt() const { return initialized_at_; }
  /// Static initialisation (static_initializer.h) from still readings: roll,
  /// pitch and gyro bias from the window, position and yaw zero. False when the
  /// readings are not still; the backend then stays uninitialised.
  bool staticInitialize(const ImuSamples& samples);
  /// When enabled and not yet initialised, the backend initialises itself from
  /// the first still window of static_window_s of IMU readings it receives.
  void setAutoStaticInitialization(bool enabled) { auto_static_init_ = enabled; }
  bool initialized() const { return initialized_; }

  // Input (each stream in non-decreasing time; earlier times throw evio::Error) -------
  void addImu(const ImuSample& sample);
  /// One synchronised set of feature positions (synchronizer.h), camera clock.
  void addMeasurementSet(const MeasurementSet& set);
  /// A laser range-finder reading (needs sensors.range_finder), camera clock.
  void addRange(TimeNs t_ns, double range_m);
  /// A zero-velocity pseudo-measurement (e.g. the event rate says the camera is still), camera clock.
  void addZeroVelocity(TimeNs t_ns);
  /// The end of the input: the full covariance test once more (it runs at
  /// most every covariance_check_interval_s of filter time while input comes).
  void finish();

  // Output --------------------------------------------------------------------------
  const BackendStatus& status() const { return status_; }
  const BackendStats& stats() const { return stats_; }
  const FilterState& state() const { return state_; }
  const BackendOptions& options() const { return options_; }
  /// The estimate at the current filter time.
  Estimate estimate() const;
  /// The estimates after each processed measurement set since the last call.
  std::vector<Estimate> takeEstimates();
  /// Measurements waiting for IMU coverage.
  std::size_t numPending() const { return pending_.size(); }

 private:
  /// diag(σ²/f_x², σ²/f_y²): a per-axis pixel σ as a covariance in normalised image units.
  Mat2 normalisedCovariance(double sigma_px) const;
  struct RangeItem {
    double range_m;
  };
  struct ZeroVelocityItem {};
  using Item = std::variant<MeasurementSet, RangeItem, ZeroVelocityItem>;

  void enqueue(TimeNs t_imu_ns, Item item);
  void process();
  void processItem(TimeNs t_ns, Item& item);
  void propagateTo(TimeNs t_ns);
  void integrateStep(const ImuSample& s1, Mat15* Phi_acc, Mat15* Q_acc);
  void tryAutoStaticInit();

  // backend_visual.cpp: the visual update, one step per function.
  void processMeasurementSet(const MeasurementSet& set);
  void augmentClone();
  /// One stacked, QR-compressed, iterated update of the gated SLAM
  /// observations and the MSCKF rows; false when it failed.
  bool stackedUpdate(const std::vector<FeatureObservation>& slam_observations, const UpdateRows& msckf_rows,
                     std::size_t c);
  /// The clone that leaves the window after this set's update, if any: the
  /// previous newest when it is closer than keyframe_interval_s to the one
  /// before it (not a keyframe), else the oldest once the window is full.
  std::optional<std::size_t> cloneToMarginalize() const;
  /// Removes clone i: SLAM features anchored on it are re-anchored on the
  /// newest clone, the tracks' observations in it are dropped.
  void marginalizeClone(std::size_t i);

  /// Divergence tests of the state and covariance; `full_test` forces the
  /// Cholesky test of the whole covariance (else it runs once per
  /// covariance_check_interval_s of filter time).
  void checkHealth(bool full_test = false);
  /// The first 2 × 2 principal minor of P + 1e-9 diag(P) that is negative
  /// (its variables i < j), if any: O(n²), implied by the Cholesky test.
  std::optional<std::pair<Eigen::Index, Eigen::Index>> negativeMinor() const;
  void setStatus(BackendStatus::Code code, const std::string& cause);
  Estimate makeEstimate() const;
  UpdaterContext updaterContext() {
    return UpdaterContext{&state_, &fej_imu_, &options_, &stats_, &innovation_, &triangulated_, &initialized_at_};
  }

  BackendOptions options_;
  BackendSensors sensors_;
  ImuNoiseDensities noise_;
  Vec3 g_W_;
  double sigma_z_;  // σ_img in normalised units
  Chi2Table slam_chi2_;
  Chi2Table msckf_chi2_;
  bool auto_static_init_ = false;


  bool initialized_ = false;
  FilterState state_;
  ImuState fej_imu_;  // the IMU state at the filter time before its updates (first estimate)
  BackendStatus status_;
  BackendStats stats_;
  std::int64_t next_clone_id_ = 0;

  // IMU: readings after the filter time, the reading at the filter time, the last raw reading.
  std::deque<ImuSample> imu_buffer_;
  ImuSample imu_at_state_;
  bool have_imu_at_state_ = false;
  ImuSample last_imu_;
  bool have_last_imu_ = false;
  TimeNs last_full_covariance_test_ns_ = std::numeric_limits<TimeNs>::min();

  std::map<std::pair<TimeNs, std::uint64_t>, Item> pending_;
  TimeNs last_set_t_ = std::numeric_limits<TimeNs>::min();
  TimeNs last_range_t_ = std::numeric_limits<TimeNs>::min();
  TimeNs last_zero_velocity_t_ = std::numeric_limits<TimeNs>::min();
  std::uint64_t next_seq_ = 0;
  TrackMap tracks_;
  std::vector<Estimate> estimates_;
  InnovationStats innovation_;  // of the visual update under way
  TriangulatedPoints triangulated_;  // for the depth prior from the map
  TimeNs initialized_at_ = 0;        // filter time of initialize()

  // The updaters (updater.h), on state_, fej_imu_, options_ and stats_.
  RangeUpdater range_;
  ZeroVelocityUpdater zero_velocity_;
  MsckfUpdater msckf_;
  SlamUpdater slam_;
};

}  // namespace evio::estimator

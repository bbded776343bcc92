#pragma once
/// @file gyro_bias_window.h
/// The first seconds of a run held back to estimate the gyroscope bias from
/// the tracks (backend/gyro_bias_from_tracks.h) before the filter sees them:
/// from the initial state on, the backend's inputs are buffered until the
/// data pass init.gyro_bias_window_s of IMU time (or end); the first
/// measurement set at or after each multiple of init.gyro_bias_keyframe_s
/// becomes a keyframe (the bearings of its informative features through the
/// camera model). Then the bias is estimated and fused with the initial
/// state's, and the buffered inputs are replayed through the filter from the
/// initial state with that bias as its mean; the bias's covariance stays the
/// prior's, because the replay gives the filter the window's tracks again.
/// If the window's IMU readings are at rest (WindowRestTest), throughout or
/// from its start until they move (the still prefix), and their mean passes
/// the χ² gate against the prior, they give both biases instead
/// (static_initializer.h restMeasurement, applyRestMeasurement), with their
/// covariance, and the rest is the initialisation itself: the filter starts
/// at its end (at rest nothing moved) and only the inputs from then on are
/// fed, so the readings the rest measurement averaged are not propagated
/// through again. Whether the camera was still too is asked of the images:
/// the informative bearings of the window's measurement sets and the still
/// probe's frame corners (FrameCorners, frontend/still_frame_probe.h), which
/// the window keeps and never buffers for the filter.
/// Memory: one window of inputs.

#include <optional>
#include <utility>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/estimator/backend/gyro_bias_from_tracks.h"
#include "evio/estimator/backend/static_initializer.h"
#include "evio/estimator/backend/still_prefix.h"
#include "evio/estimator/measurements.h"
#include "evio/estimator/pipeline/backend_input.h"

namespace evio::estimator {

/// When the window's IMU counts as at rest (the static initialiser's bounds).
struct WindowRestTest {
  bool enabled = false;
  double gravity_mps2 = 9.81;
  double max_acc_std_mps2 = 0.1;     ///< per-axis spread bound, m/s²
  double max_gyro_std_radps = 0.02;  ///< rad/s
  ImuNoiseDensities noise;           ///< the filter's IMU noise
  /// Where the rest ends (backend/still_prefix.h): the whole window if no
  /// block moves, else a still prefix spanning at least prefix.min_s, whose
  /// rest measurement carries the tests' allowances. prefix.min_s = 0: the
  /// spread test alone, on the whole window.
  StillPrefixTest prefix{0.05, 4.0, 0.0};
  /// The still tracks' noise per axis for the images' test, px: a tracker
  /// on a still scene moves its points by hundredths of a pixel (KLT 0.009
  /// px, EKLT 0.004 px median over boxes_6dof's first 0.2 s), so 0.1; more
  /// for a track source with stated noise (the tracks method's noise_px).
  double still_track_sigma_px = 0.1;
};

class GyroBiasWindow {
 public:
  GyroBiasWindow(double window_s, double keyframe_s, const Camera& camera, const Mat3& R_B_C,
                 TimeNs time_offset_cam_imu_ns, const WindowRestTest& rest_test = {},
                 const GyroBiasFromTracksOptions& solver = {});

  /// Opens the window at the initial state x0 (IMU clock).
  void open(const ImuState& x0);
  /// Open and not yet complete: inputs go to add().
  bool collecting() const { return x0_.has_value() && !complete_; }
  /// Buffers one input; true once an IMU reading reaches the window's end.
  bool add(BackendInput in);
  /// The estimate from what the window holds (prior: x0's bias and the bias
  /// block of P0); the window is then closed.
  /// The estimate from what the window holds, given the initial state's
  /// covariance P0 (its bias block is the tracks' prior). At rest (at_rest
  /// set) restStart() holds the updated state at the window's end and its
  /// covariance; the window is then closed.
  GyroBiasEstimate estimate(const Eigen::Matrix<double, 15, 15>& P0);
  /// At rest: the filter's start, the window's end, and its covariance.
  const std::optional<std::pair<ImuState, Eigen::Matrix<double, 15, 15>>>& restStart() const { return rest_start_; }
  /// The buffered inputs at or after t_imu_ns (IMU clock), in their order, moved out.
  std::vector<BackendInput> takeInputsFrom(TimeNs t_imu_ns);
  const ImuState& initialState() const { return *x0_; }
  /// init.gyro_bias_window_tracks_once: the filter takes the tracks' estimate
  /// with its covariance and, of the window's inputs, only the IMU and range
  /// readings (the window's tracks are used once, by the window).
  void setTracksOnce(bool on) { tracks_once_ = on; }
  bool tracksOnce() const { return tracks_once_; }
  /// init.gyro_bias_window_sigma=window: the replay starts with the tracks'
  /// covariance for the bias instead of the prior's.
  void setReplayWithWindowSigma(bool on) { replay_with_window_sigma_ = on; }
  bool replayWithWindowSigma() const { return replay_with_window_sigma_; }
  /// The buffered inputs in their order, moved out.
  std::vector<BackendInput> takeInputs() { return std::move(inputs_); }

 private:
  void addKeyframe(const MeasurementSet& set, TimeNs t_imu_ns);
  /// The rest measurement as one update of x0 and P0; on success *e holds
  /// the biases and restStart() the state at the rest's end.
  void applyRest(const RestMeasurement& rest, const Eigen::Matrix<double, 15, 15>& P0, GyroBiasEstimate* e);
  /// The still test is on (the rest test with prefix.min_s > 0).
  bool stillTestOn() const { return rest_test_.enabled && rest_test_.prefix.min_s > 0.0; }
  /// The still test (rest_test_.prefix): on rest, *e holds the biases and
  /// restStart() the state at the rest's end.
  void tryStillRest(const Eigen::Matrix<double, 15, 15>& P0, GyroBiasEstimate* e);
  /// Keeps the set's informative bearings for the images' still test.
  void addStillObservations(const MeasurementSet& set, TimeNs t_imu_ns);
  /// Keeps the still probe's corners (as negative ids) for the same test.
  void addStillCorners(const FrameCorners& corners);
  /// The images' still test up to t1 (backend/still_prefix.h
  /// imageRotationRate at rest_test.still_track_sigma_px per axis, χ²₃ gate
  /// at 0.999): kStill, with the variance of the rate the gate could miss in
  /// *missed_variance; kMoving when the gate fails; kCannotTell with fewer
  /// than five corners or features seen twice.
  /// Records the test in *e.
  enum class ImageVerdict { kStill, kMoving, kCannotTell };
  ImageVerdict imagesStill(TimeNs t1_ns, double* missed_variance, GyroBiasEstimate* e) const;

  double window_s_, keyframe_s_;
  Camera camera_;
  Mat3 R_B_C_;
  TimeNs offset_ns_;
  WindowRestTest rest_test_;
  GyroBiasFromTracksOptions solver_;
  std::optional<std::pair<ImuState, Eigen::Matrix<double, 15, 15>>> rest_start_;
  bool tracks_once_ = false;
  bool replay_with_window_sigma_ = false;
  std::optional<ImuState> x0_;
  bool complete_ = false;
  TimeNs next_keyframe_ns_ = 0;
  std::vector<BackendInput> inputs_;
  ImuSamples imu_;
  std::vector<BearingKeyframe> keyframes_;
  std::vector<BearingObservation> still_observations_;
};

}  // namespace evio::estimator

#pragma once
/// @file klt_tracker.h
/// The frame-based KLT-VIO frontend (docs/algorithms.md#klt): FAST corners,
/// pyramidal Lucas–Kanade between consecutive frames, and RANSAC on the
/// fundamental matrix (8-point model) to reject outliers. The RANSAC
/// threshold is a distance in pixels of an ideal pinhole camera with the
/// calibrated focal length: points are undistorted with the camera model to
/// normalised coordinates and scaled by fx before RANSAC, so the threshold
/// means the same whatever the distortion. Track points are emitted at frame
/// times; events are ignored.
///
/// With `imu_prediction` each live feature's search starts where the gyro's
/// rotation since the previous frame moves it (gyro_predictor.h: the
/// feature taken as infinitely far, the bias not removed), not where it was:
/// Lucas–Kanade then only has to find the translation's parallax and the
/// prediction's error, which keeps tracks through rotations whose image
/// motion between frames is more than the pyramid covers.

#include <memory>
#include <optional>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/core/options.h"
#include "evio/core/pose.h"
#include "evio/estimator/frontend/feature_tracker.h"
#include "evio/estimator/frontend/gyro_predictor.h"

namespace evio::estimator {

struct KltOptions {
  int max_features = 60;             ///< detect up to this many live features
  int min_features = 45;             ///< re-detect when fewer are alive
  int fast_threshold = 20;           ///< FAST threshold, grey levels
  bool fast_nonmax_suppression = true;
  double min_distance_px = 9.0;      ///< between features
  int border_px = 10;                ///< no detection this close to the edge
  int window_px = 21;                ///< Lucas–Kanade window side
  int pyramid_levels = 3;            ///< pyramid levels (OpenCV maxLevel = levels − 1)
  int max_iterations = 30;           ///< Lucas–Kanade iterations per level
  double lk_epsilon = 0.01;          ///< Lucas–Kanade stopping step, px
  bool ransac = true;                ///< fundamental-matrix RANSAC
  double ransac_threshold_px = 0.6;  ///< epipolar distance, px of the undistorted image
  double ransac_confidence = 0.99;   ///< RANSAC confidence
  bool imu_prediction = false;       ///< start each search at the gyro's prediction (needs IMU and T_B_C)
  /// Forward–backward check, px (0: off): Lucas–Kanade is run back from
  /// each tracked point into the previous frame, started where the forward
  /// search's start lay relative to the feature, and the point is lost when
  /// it lands farther than this from where the feature was. A jump to a
  /// wrong minimum (an exposure step between frames, a motion beyond the
  /// pyramid) rarely leads back to its start.
  double backward_check_px = 0.0;
  /// Time constant of the track error stated with every point, s (0:
  /// independent; as EkltOptions::error_time_s).
  double error_time_s = 0.0;
  /// σ of each point's position, px per axis, stated with every point as its
  /// covariance σ² I (TrackPoint::cov_px); the backend then weighs the point
  /// by it instead of its own σ_img. 0: none stated (σ_img).
  double position_sigma_px = 0.0;

  template <class V>
  void fields(V& v) {
    v("max_features", max_features, "detect up to this many live features");
    v("min_features", min_features, "re-detect when fewer are alive");
    v("fast_threshold", fast_threshold, "FAST threshold, grey levels");
    v("fast_nonmax_suppression", fast_nonmax_suppression, "FAST non-maximum suppression");
    v("min_distance_px", min_distance_px, "minimum distance between features, px");
    v("border_px", border_px, "detection border, px");
    v("window_px", window_px, "Lucas-Kanade window side, px");
    v("pyramid_levels", pyramid_levels, "pyramid levels");
    v("max_iterations", max_iterations, "Lucas-Kanade iterations per level");
    v("lk_epsilon", lk_epsilon, "Lucas-Kanade stopping step, px");
    v("ransac", ransac, "fundamental-matrix RANSAC");
    v("ransac_threshold_px", ransac_threshold_px, "RANSAC threshold, px of the undistorted image");
    v("ransac_confidence", ransac_confidence, "RANSAC confidence");
    v("imu_prediction", imu_prediction, "start each Lucas-Kanade search at the gyro's prediction");
    v("backward_check_px", backward_check_px, "lose a point whose backward Lucas-Kanade lands farther than this from its start, px (0: off)");
    v("error_time_s", error_time_s, "time constant of the track error stated with each point, s (0: independent)");
    v("position_sigma_px", position_sigma_px, "position sigma stated with each point, px (0: none, the backend's sigma_img)");
  }
  void validate() const;
};

class KltTracker final : public FeatureTracker {
 public:
  /// `T_B_C` (camera into body frame) is needed with `imu_prediction` only.
  KltTracker(const KltOptions& options, const Camera& camera, std::optional<Pose> T_B_C = std::nullopt);

  void addFrame(TimeNs t_ns, const cv::Mat& image) override;
  using FeatureTracker::addEvents;
  void addEvents(const EventArray&, std::size_t, std::size_t) override {}
  void addImu(const ImuSample& sample) override;
  bool usesImu() const override { return predictor_ != nullptr; }
  void drainTrackPoints(TrackPoints& out) override;
  std::size_t numAlive() const override { return ids_.size(); }
  std::string_view name() const override { return "klt"; }

 private:
  KltOptions options_;
  Camera camera_;
  cv::Mat previous_;
  TimeNs previous_t_ns_ = 0;
  std::vector<FeatureId> ids_;
  std::vector<Vec2> points_;
  FeatureId next_id_ = 0;
  TrackPoints out_;
  std::unique_ptr<GyroPredictor> predictor_;  ///< with imu_prediction

  /// Where each live feature's search starts in the frame at t_ns.
  std::vector<cv::Point2f> searchStarts(TimeNs t_ns) const;
};

}  // namespace evio::estimator

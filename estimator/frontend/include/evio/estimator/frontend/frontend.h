#pragma once
/// @file frontend.h
/// The frontend as the pipelines and `evio track` use it: an optional
/// event-based image reconstruction and one tracker (EKLT, KLT or HASTE) behind the
/// FeatureTracker interface. Inputs in time order (feature_tracker.h). The
/// event pre-filters (event_prefilter.h, options `prefilter`) run before it:
/// the pipeline's PrefilterStage, or the caller.

#include <map>
#include <memory>
#include <optional>
#include <string>

#include "evio/core/camera/camera.h"
#include "evio/core/pose.h"
#include "evio/estimator/frontend/eklt_options.h"
#include "evio/estimator/frontend/event_prefilter.h"
#include "evio/estimator/frontend/feature_tracker.h"
#include "evio/estimator/frontend/haste_options.h"
#include "evio/estimator/frontend/image_reconstructor.h"
#include "evio/estimator/frontend/klt_tracker.h"
#include "evio/estimator/frontend/track_lag.h"

namespace evio::estimator {

struct FrontendOptions {
  std::string tracker = "eklt";          ///< eklt | klt | haste
  std::string image_source = "frames";   ///< frames | reconstructed (from events)
  /// Threads tracking features in parallel (EKLT and HASTE; KLT uses one).
  /// The output is byte-identical for any value (eklt_tracker.h).
  int threads = 1;
  /// With threads > 1, `evio estimate` tracks the event chunks of up to this
  /// span of data (s, counted from the first held chunk's end) in one call
  /// (FeatureTracker::addEventChunks), holding the inputs between them, so
  /// that the threads share the work of many chunks instead of one IMU
  /// period's. The held inputs reach the synchroniser and the backend side
  /// in their order, one by one, so every output file is the same; only the
  /// estimates' latency grows, by up to this span plus one chunk. Applies
  /// where nothing between the chunks changes the tracker (EKLT or HASTE on
  /// sensor frames, no gyro prediction); 0: every chunk alone. (`evio track`
  /// hands the tracker whole files' chunks itself.)
  double segment_s = 0.05;
  EventPrefilterOptions prefilter;  ///< for the pre-filter that runs before the frontend
  EkltOptions eklt;
  KltOptions klt;
  HasteOptions haste;
  ImageReconstructorOptions reconstruction;
  TrackLagOptions track_lag;  ///< the event tracker's lag estimated from the frames (track_lag.h)

  template <class V>
  void fields(V& v) {
    v("tracker", tracker, "eklt, klt or haste");
    v("image_source", image_source, "frames or reconstructed");
    v("threads", threads, "threads tracking features in parallel (EKLT, HASTE), same output for any value");
    v("segment_s", segment_s, "event chunks of up to this span tracked in one call (0: each alone), same estimates");
    v("prefilter", prefilter, "event pre-filters");
    v("eklt", eklt, "EKLT tracker");
    v("klt", klt, "KLT tracker");
    v("haste", haste, "HASTE tracker");
    v("reconstruction", reconstruction, "event-based image reconstruction");
    v("track_lag", track_lag, "online estimate of the event tracker's lag");
  }
  void validate() const;
};

/// The options with what the event camera's calibration states filled in:
/// eklt.batch_contrast_threshold = 0 becomes the mean of the camera's
/// `contrast_threshold_pos` and `contrast_threshold_neg` parameters
/// (sensors.yaml), or kDavis240cContrastThreshold when it states neither.
/// A stated option is kept. The pipeline and `evio track` call it, so the
/// resolved value is what their config.yaml / tracks.txt.yaml record.
FrontendOptions resolveSensorParameters(FrontendOptions options,
                                        const std::map<std::string, double>& event_camera_parameters);

class Frontend {
 public:
  /// `camera` is the event camera (EKLT, HASTE) or frame camera (KLT); `T_B_C` is
  /// needed for a gyro prediction only (eklt.imu_prediction, klt.imu_prediction).
  Frontend(const FrontendOptions& options, const Camera& camera, std::optional<Pose> T_B_C = std::nullopt);
  ~Frontend();

  /// Events (non-decreasing time, already pre-filtered): integrated into the
  /// reconstruction (which may emit frames in between), then tracked.
  void addEvents(const EventArray& events);
  /// A sensor frame (CV_8UC1): to the tracker (image_source frames) or fused
  /// into the reconstruction (image_source reconstructed).
  void addFrame(TimeNs t_ns, const cv::Mat& image);
  void addImu(const ImuSample& sample);

  /// Appends the track points since the last call (the lag probe sees them
  /// too), each stating the tracker's error time constant (error_time_s of
  /// its options section) and, where the tracker states no covariance of its
  /// own, its section's position_sigma_px as σ² I (KLT and HASTE).
  void drainTrackPoints(TrackPoints& out);
  /// True when the events of several chunks may be tracked in one call:
  /// nothing but events changes the tracker between them (no reconstruction;
  /// a tracker that does not use the IMU, FeatureTracker::usesImu).
  bool tracksEventChunks() const;
  /// True when the tracker takes the IMU (a gyro prediction,
  /// FeatureTracker::usesImu): addImu then matters.
  bool usesImu() const;
  /// The chunks [0, e0), [e0, e1), … of `events` (FeatureTracker::addEventChunks):
  /// the same as addEvents and drainTrackPoints chunk by chunk.
  void addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends, TrackPoints& out,
                      std::vector<std::size_t>& point_ends);
  /// The event tracker's lag estimated from the frames (track_lag.estimate,
  /// EKLT and HASTE on sensor frames); nullopt while there are too few samples.
  std::optional<TrackLag> trackLag() const { return probe_ ? probe_->lag() : std::nullopt; }
  FeatureTracker& tracker() { return *tracker_; }
  const FeatureTracker& tracker() const { return *tracker_; }

  /// Events given to addEvents().
  std::uint64_t numEvents() const { return events_; }
  std::uint64_t numReconstructedFrames() const { return reconstructed_frames_; }

 private:
  /// points[begin, end) take the tracker's error time constant and stated σ.
  void stateNoise(TrackPoints& points, std::size_t begin) const;
  /// With images rebuilt from events, the points the tracker measured on
  /// them lag as the events do: points[begin, end) lose measured_on_frame.
  void unmarkReconstructedFramePoints(TrackPoints& points, std::size_t begin) const;

  FrontendOptions options_;
  double error_time_s_ = 0.0;       ///< the tracker's options' error_time_s
  double position_sigma_px_ = 0.0;  ///< KLT's or HASTE's position_sigma_px (EKLT states its own covariance)
  std::unique_ptr<FeatureTracker> tracker_;
  std::unique_ptr<ImageReconstructor> reconstructor_;
  std::unique_ptr<FrameLagProbe> probe_;
  std::uint64_t events_ = 0;
  std::uint64_t reconstructed_frames_ = 0;
};

}  // namespace evio::estimator

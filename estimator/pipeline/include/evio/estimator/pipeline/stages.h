#pragma once
/// @file stages.h
/// The estimator's stages, in the order data flows (pipeline.h wires them):
///
///   SequenceReader ─SequenceItem─► PrefilterStage ─SequenceItem─► FrontendStage
///     ─FrontendOutput─► SynchronizerStage ─BackendInput─► BackendStage ─Estimate─►
///     HealthMonitor (health_monitor.h) ─Estimate─► EstimateWriter
///
/// The `tracks` method replaces prefilter, frontend and synchroniser by
/// TracksStage (SequenceItem → BackendInput). IMU and range readings travel
/// down the chain with the visual data, so every stage sees one time-ordered
/// stream. Times are on the camera clock except the IMU samples' own t_ns
/// (IMU clock, t_imu = t_cam + offset).

#include <cstdint>
#include <memory>
#include <optional>
#include <variant>
#include <vector>

#include "evio/estimator/backend/backend.h"
#include "evio/estimator/frontend/eklt_tracker.h"
#include "evio/estimator/frontend/event_prefilter.h"
#include "evio/estimator/frontend/frontend.h"
#include "evio/estimator/frontend/still_frame_probe.h"
#include "evio/estimator/frontend/synchronizer.h"
#include "evio/estimator/measurements.h"
#include "evio/estimator/pipeline/backend_input.h"
#include "evio/estimator/pipeline/groundtruth_init.h"
#include "evio/estimator/pipeline/gyro_bias_window.h"
#include "evio/estimator/pipeline/sequence_reader.h"
#include "evio/estimator/pipeline/stage.h"
#include "evio/estimator/pipeline/tracks_input.h"

namespace evio::estimator {

/// What the frontend passes on for one input.
struct FrontendOutput {
  SequenceItem::Kind kind = SequenceItem::Kind::kEvents;
  TimeNs t_ns = 0;              ///< camera clock
  TrackPoints points;           ///< kEvents, kFrame: the track points the input produced
  std::uint64_t events = 0;     ///< kEvents: events that reached the tracker
  ImuSample imu;                ///< kImu (IMU clock)
  io::RangeSample range;        ///< kRange
  /// kFrame: the frontend's estimate of its tracker's lag after this frame
  /// (frontend.track_lag.estimate), for the synchroniser to compensate.
  std::optional<TrackLag> lag;
  /// kFrame, in the still probe's span: the first frame's corners here.
  std::optional<FrameCorners> still_corners;
};

/// Event pre-filters (event_prefilter.h); other items pass unchanged.
class PrefilterStage : public Stage<SequenceItem, SequenceItem> {
 public:
  PrefilterStage(const EventPrefilterOptions& options, int width, int height);
  void process(SequenceItem& in, std::vector<SequenceItem>& out) override;
  std::uint64_t numEventsSeen() const { return seen_; }
  std::uint64_t numEventsKept() const { return kept_; }

 private:
  std::unique_ptr<EventPrefilter> filter_;  // null: pass-through
  EventArray filtered_;
  std::uint64_t seen_ = 0, kept_ = 0;
};

/// The tracker (EKLT or KLT, with the optional reconstruction): events and
/// frames in, track points out; IMU samples feed its gyro prediction.
///
/// Segments (FrontendOptions::segment_s, with threads > 1): where only
/// events change the tracker between chunks (EKLT or HASTE), event inputs,
/// and the IMU inputs that come after a held one, are held until their span
/// reaches segment_s or they hold kMaxSegmentEvents events (or a frame or
/// range reading comes, or the data end: finish); the held chunks are
/// tracked in one call, and the held inputs leave in their order, one output
/// per input, each event input with its own chunk's points: the next stages
/// see exactly what they would see input by input.
class FrontendStage : public Stage<SequenceItem, FrontendOutput> {
 public:
  /// still_probe_s > 0: the frames of the first still_probe_s also go to a
  /// StillFrameProbe (still_frame_probe.h), whose corners the outputs carry.
  FrontendStage(const FrontendOptions& options, const CameraSensor& camera, double still_probe_s = 0.0);
  void process(SequenceItem& in, std::vector<FrontendOutput>& out) override;
  /// At the end of the data: the held inputs leave.
  void finish(std::vector<FrontendOutput>& out) { flushSegment(out); }
  /// Inputs held in a segment, waiting for finish() or the next input.
  bool holding() const { return !held_.empty(); }
  std::uint64_t numFrames() const { return frames_; }
  /// The EKLT tracker's own time split; null for the other trackers.
  const EkltTiming* ekltTiming() const;
  /// CPU time of the features tracked in parallel (worker_pool.h).
  WorkerPool::Cpu trackerParallelCpu() const { return frontend_.tracker().parallelCpu(); }
  /// The frontend's current estimate of its tracker's lag (track_lag.h).
  std::optional<TrackLag> trackLag() const { return frontend_.trackLag(); }

 private:
  void processNow(SequenceItem& in, std::vector<FrontendOutput>& out);
  /// Holds an event or IMU input; true when the segment is full.
  bool hold(SequenceItem& in);
  void flushSegment(std::vector<FrontendOutput>& out);

  /// A held input: its output, and for events the end of its chunk in segment_events_.
  struct Held {
    FrontendOutput output;
    std::size_t events_end = 0;
  };
  static constexpr std::size_t kMaxSegmentEvents = std::size_t{1} << 20;  // memory bound at any event rate

  Frontend frontend_;
  StillFrameProbe still_probe_;
  std::uint64_t frames_ = 0;
  TimeNs segment_ns_ = 0;  // 0: no segments
  std::vector<Held> held_;
  EventArray segment_events_;
  std::vector<std::size_t> chunk_ends_, point_ends_;
  TrackPoints segment_points_;
};

/// Asynchronous track points → measurement sets (synchronizer.h); IMU and
/// range readings pass on to the backend, each before the sets it released.
class SynchronizerStage : public Stage<FrontendOutput, BackendInput> {
 public:
  explicit SynchronizerStage(const SynchronizerOptions& options) : sync_(options) {}
  void process(FrontendOutput& in, std::vector<BackendInput>& out) override;
  std::uint64_t numTrackPoints() const { return track_points_; }

 private:
  Synchronizer sync_;
  std::uint64_t track_points_ = 0;
};

/// The `tracks` method: measurement sets from a tracks file (tracks_input.h).
class TracksStage : public Stage<SequenceItem, BackendInput> {
 public:
  explicit TracksStage(std::unique_ptr<TracksInput> input) : input_(std::move(input)) {}
  void process(SequenceItem& in, std::vector<BackendInput>& out) override;

 private:
  std::unique_ptr<TracksInput> input_;
  std::vector<MeasurementSet> sets_;
};

/// The EKF (backend.h): initialised from ground truth when the caller gave
/// an initializer, else by the backend's own static initialisation. With a
/// gyroscope-bias window (gyro_bias_window.h) the initial state's bias comes
/// from the window's tracks, and the window's inputs reach the filter after it.
class BackendStage : public Stage<BackendInput, Estimate> {
 public:
  BackendStage(Backend& backend, std::optional<GroundTruthInitializer> initializer,
               std::optional<GyroBiasWindow> gyro_bias_window = std::nullopt);
  void process(BackendInput& in, std::vector<Estimate>& out) override;
  /// At the end of the data: a window still open is closed with what it holds.
  void finish(std::vector<Estimate>& out);
  std::uint64_t numMeasurementSets() const { return measurement_sets_; }
  /// Features in the latest measurement set received (0 before the first):
  /// timing.txt's features column.
  std::size_t lastSetFeatures() const { return last_set_features_; }
  /// The window's estimate, once it closed.
  const std::optional<GyroBiasEstimate>& gyroBiasEstimate() const { return gyro_bias_; }

 private:
  void feed(BackendInput& in, std::vector<Estimate>& out);
  void closeWindow(std::vector<Estimate>& out);
  /// Initialises the backend at the window's close and records the bias block
  /// of P in the estimate (filter_start_covariance).
  void startFilter(const ImuState& x0, const Eigen::Matrix<double, 15, 15>& P);

  Backend& backend_;
  std::optional<GroundTruthInitializer> initializer_;
  std::optional<GyroBiasWindow> window_;
  std::optional<GyroBiasEstimate> gyro_bias_;
  std::uint64_t measurement_sets_ = 0;
  std::size_t last_set_features_ = 0;
};

}  // namespace evio::estimator

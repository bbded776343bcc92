#pragma once
/// @file eklt_tracker.h
/// EKLT (Gehrig et al., IJCV 2019) as used by EKLT-VIO (Mahlknecht et al. 2022,
/// Frontend): Harris corners detected on frames; per feature a template of
/// the log-image gradient; events splatted bilinearly into a P×P patch
/// around the feature; when the patch holds an adaptive number of events the
/// rigid warp and the flow direction are optimised (eklt_cost.h), the batch
/// is discarded (each batch used once) and the feature moves. The tracking
/// quality threshold is the only outlier test. New features are bootstrapped
/// by pyramidal KLT between their detection frame and the next frame.
///
/// Known bias (measured in tests/estimator/eklt_tracker_test.cpp): a real
/// pixel's hysteresis (after an event it must change by a full contrast
/// threshold C in the other direction to fire again) makes the event image
/// trail a moving edge by about C/(2|∇L|) px, which the linearised model does
/// not include; on the test texture this is ~0.2 px at C = 0.05 and ~0.04 px
/// at C = 0.01, along the flow.
///
/// Memory is fixed after construction (max_features slots, a per-pixel
/// feature bitmask); processing an event allocates nothing.
///
/// Threads (`threads` > 1): the features are tracked in parallel with a fixed
/// partition, slot s on part s mod threads (worker_pool.h); each part has its
/// own pixel bitmask and scratch and walks the whole event chunk for its own
/// features. A feature's result depends only on its own events, and the
/// parts' track points are merged in the single-thread order (by event, then
/// slot), so the output is byte-identical for any thread count. Frames are
/// handled on the calling thread.

#include <memory>
#include <optional>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/core/pose.h"
#include "evio/estimator/frontend/eklt_options.h"
#include "evio/estimator/frontend/chunk_points.h"
#include "evio/estimator/frontend/eklt_solver.h"
#include "evio/estimator/frontend/feature_grid.h"
#include "evio/estimator/frontend/feature_tracker.h"
#include "evio/estimator/frontend/gradient_template.h"
#include "evio/estimator/frontend/gyro_predictor.h"
#include "evio/estimator/frontend/worker_pool.h"

namespace evio::estimator {

/// Cumulative processing time by stage, seconds of wall time, summed over the
/// tracker's threads.
struct EkltTiming {
  double events_s = 0.0;        ///< addEvents in total (splatting + optimisation)
  double optimisation_s = 0.0;  ///< inside the solver and its bookkeeping
  double detection_s = 0.0;     ///< Harris detection and template extraction
  double bootstrap_s = 0.0;     ///< bootstrap KLT
  double frame_s = 0.0;         ///< addFrame in total (log image, gradients, the two above)
  std::uint64_t events = 0;         ///< events received
  std::uint64_t events_in_patches = 0;  ///< (event, feature) splats
  std::uint64_t optimisations = 0;
  std::uint64_t solver_iterations = 0;
  std::uint64_t reversal_solves = 0;  ///< second solves from φ + π (EkltOptions::reversal_quality)
  std::uint64_t batches_dropped = 0;  ///< batches without a plausible solution (max_batch_shift_px)
  /// Splatting and lookup: events_s − optimisation_s.
  double splattingS() const { return events_s - optimisation_s; }
};

class EkltTracker final : public FeatureTracker {
 public:
  /// `camera`: the event camera (resolution; projection for the gyro
  /// prediction). `T_B_C` is needed only when options.imu_prediction.
  /// `threads` ≥ 1: features tracked in parallel (see the file comment).
  EkltTracker(const EkltOptions& options, const Camera& camera, std::optional<Pose> T_B_C = std::nullopt,
              int threads = 1);
  ~EkltTracker() override;

  void addFrame(TimeNs t_ns, const cv::Mat& image) override;
  using FeatureTracker::addEvents;
  void addEvents(const EventArray& events, std::size_t begin, std::size_t end) override;
  void addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends, TrackPoints& out,
                      std::vector<std::size_t>& point_ends) override;
  void addImu(const ImuSample& sample) override;
  bool usesImu() const override { return predictor_ != nullptr; }
  void drainTrackPoints(TrackPoints& out) override;
  std::size_t numAlive() const override;
  std::string_view name() const override { return "eklt"; }
  WorkerPool::Cpu parallelCpu() const override { return pool_ ? pool_->cpu() : WorkerPool::Cpu{}; }

  /// Starts a feature by hand, bypassing detection and bootstrap: template
  /// from (gx, gy) of a log image around x0 (the position at the template
  /// frame), current position `uv` at time t_ns, rotation θ and flow angle φ.
  /// Returns its id. For tests and for callers with their own detector. Its
  /// one point (kNew at t_ns) is marked measured_on_frame: the caller's
  /// position is taken as lag-free, as a detection is.
  FeatureId addFeature(const cv::Mat& log_image, const Vec2& x0, const Vec2& uv, TimeNs t_ns,
                       double flow_angle_rad, double theta_rad = 0.0);

  /// State of a live feature (nullopt when not alive).
  struct FeatureState {
    Vec2 uv;            ///< current position, px
    double theta_rad;   ///< warp rotation
    double flow_angle_rad;
    int batch_size;     ///< events that trigger the next optimisation
    double quality;
  };
  std::optional<FeatureState> feature(FeatureId id) const;

  const EkltTiming& timing() const { return timing_; }
  const EkltOptions& options() const { return options_; }

 private:
  struct Slot;
  struct Part;
  void splat(Slot& s, double x, double y, bool positive, TimeNs t_ns);
  void trackChunk(Part& part, const EventArray& events, std::size_t begin, std::size_t end);
  /// Events [begin, end) through every part (one run of the threads); their
  /// points stay in the parts for the merge.
  void trackInParts(const EventArray& events, std::size_t begin, std::size_t end);
  void mergeChunkPoints();
  void optimise(Part& part, int slot_index, std::size_t event_index);
  /// The last position of slot `s` moved by the gyro's rotation from then
  /// to t (imu_prediction); nullopt without a prediction or when it cannot
  /// be made.
  std::optional<Vec2> rotatedCentre(const Slot& s, TimeNs t) const;
  /// Where the feature of slot `s` is expected at time t: `rotated` and,
  /// with imu_prediction_translation_window_s, its translational velocity
  /// times the time since; or the last position itself (no rotation, or a
  /// prediction shorter than imu_prediction_min_shift_px).
  Vec2 predictedCentre(const Slot& s, const std::optional<Vec2>& rotated, TimeNs t) const;
  /// With imu_prediction_translation_window_s: the feature of slot `s`,
  /// still at its last position, is accepted at uv at time t; its derotated
  /// path grows by the step less the gyro's rotation over it (`rotated`,
  /// the last position when there is none).
  void addDerotatedStep(Slot& s, const Vec2& uv, const std::optional<Vec2>& rotated, TimeNs t) const;
  /// The batch's solution from p0, re-solved from the reversed flow when
  /// implausible (EkltOptions::reversal_quality, max_batch_shift_px);
  /// nullopt when neither moves the feature plausibly (an invalid solution
  /// is returned as it is: the feature is lost). Counts in `timing`.
  std::optional<EkltSolution> solveBatch(const Slot& s, const EkltBatch& batch, const Vec4& p0, const Vec2& predicted,
                                         EkltTiming& timing) const;
  void activate(int slot_index, const Vec2& uv, TimeNs t_ns, double flow_angle);
  void lose(Part& part, int slot_index, std::size_t event_index);
  void free(int slot_index);
  Part& partOf(int slot_index) { return *parts_[static_cast<std::size_t>(slot_index) % parts_.size()]; }
  void resetPatch(Slot& s);
  PixelRect patchRect(const Vec2& centre) const;
  int freeSlot() const;
  void assignTemplate(Slot& s, const cv::Mat& gx, const cv::Mat& gy, const Vec2& x0);
  int batchSize(double abs_sum) const;

  EkltOptions options_;
  EkltSolverKind solver_;
  EkltSolverSettings settings_;
  Camera camera_;
  int width_;
  int height_;
  int half_;                      // h = (P − 1)/2
  int template_radius_;
  std::vector<Slot> slots_;
  std::vector<std::unique_ptr<Part>> parts_;  // slot s belongs to part s mod parts_.size()
  std::unique_ptr<WorkerPool> pool_;          // null with one thread
  std::vector<std::vector<ChunkPoint>*> part_points_;  // each part's points, for the merge
  std::unique_ptr<GyroPredictor> predictor_;
  TrackPoints out_;
  FeatureId next_id_ = 0;
  cv::Mat previous_frame8_;
  TimeNs previous_frame_t_ns_ = 0;
  EkltTiming timing_;
};

}  // namespace evio::estimator

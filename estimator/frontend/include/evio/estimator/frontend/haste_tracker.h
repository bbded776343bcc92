#pragma once
/// @file haste_tracker.h
/// HASTE as a frontend tracker (the tracker of HASTE-VIO in Mahlknecht et
/// al. 2022): features seeded at Harris corners of frames (sensor frames, or
/// frames reconstructed from events, so it runs on events alone), each then
/// tracked by its own HasteFeature on the events alone (haste_feature.h).
///
/// Track points: kNew when a feature's window first fills (its seed position
/// at the middle event's time), kTracked at every state jump (the new state
/// at the middle event's time), kLost when the state comes within
/// lost_border_px of the image edge. Between jumps a feature emits nothing:
/// the synchroniser extrapolates from the last two jumps.
///
/// Seeding: on a frame, when fewer than min_features are alive, Harris
/// corners (feature_detection.h) away from live features and at least
/// max(lost_border_px, h) + 1 px from the edge, up to max_features. With
/// centered_initialization the seed's window starts with the in-range events
/// among the last history_events events (up to (N − 1)/2 of them), so its
/// first state is at about the frame's time. A seed whose window has not
/// filled seed_timeout_s after its frame is dropped without a track point.
///
/// Memory is fixed at construction (max_features features, a per-pixel
/// bitmask, the event history ring); processing an event allocates nothing.

#include <memory>
#include <optional>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/estimator/frontend/chunk_points.h"
#include "evio/estimator/frontend/feature_grid.h"
#include "evio/estimator/frontend/feature_tracker.h"
#include "evio/estimator/frontend/haste_feature.h"
#include "evio/estimator/frontend/haste_options.h"
#include "evio/estimator/frontend/worker_pool.h"

namespace evio::estimator {

/// Counters of a run (for the benchmark and `evio track`).
struct HasteCounters {
  std::uint64_t events = 0;            ///< events received
  std::uint64_t feature_updates = 0;   ///< (event, started feature) score updates
  std::uint64_t jumps = 0;             ///< state jumps
};

class HasteTracker final : public FeatureTracker {
 public:
  /// `camera`: the event camera (its resolution and the frames' size).
  /// `threads` ≥ 1: features tracked in parallel, slot s on part s mod
  /// threads with its own pixel bitmask, points merged in the single-thread
  /// order (chunk_points.h): the same output for any thread count.
  HasteTracker(const HasteOptions& options, const Camera& camera, int threads = 1);
  ~HasteTracker() override;

  void addFrame(TimeNs t_ns, const cv::Mat& image) override;
  using FeatureTracker::addEvents;
  void addEvents(const EventArray& events, std::size_t begin, std::size_t end) override;
  void addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends, TrackPoints& out,
                      std::vector<std::size_t>& point_ends) override;
  void addImu(const ImuSample&) override {}
  void drainTrackPoints(TrackPoints& out) override;
  std::size_t numAlive() const override;
  std::string_view name() const override { return "haste"; }
  WorkerPool::Cpu parallelCpu() const override { return pool_ ? pool_->cpu() : WorkerPool::Cpu{}; }

  /// Seeds a feature by hand at `uv`, time t_ns, rotation θ (as a frame's
  /// corner would be, with the centred initialisation). Returns its id.
  FeatureId addFeature(const Vec2& uv, TimeNs t_ns, double theta_rad = 0.0);
  /// The state of a started feature (nullopt when not started or not alive).
  std::optional<HasteState> feature(FeatureId id) const;

  const HasteCounters& counters() const { return counters_; }
  const HasteOptions& options() const { return options_; }

 private:
  struct Slot;
  struct Part;
  Part& partOf(int index) { return *parts_[static_cast<std::size_t>(index) % parts_.size()]; }
  void trackChunk(Part& part, const EventArray& events, std::size_t begin, std::size_t end);
  /// Events [begin, end) through every part (one run of the threads); their
  /// points stay in the parts for the merge.
  void trackInParts(const EventArray& events, std::size_t begin, std::size_t end);
  /// Records the history of events [begin, end), once they are tracked.
  void afterTracking(const EventArray& events, std::size_t begin, std::size_t end);
  PixelRect rangeRect(double x, double y) const;
  int freeSlot() const;
  void seed(int index, const Vec2& uv, TimeNs t_ns, double theta);
  void moveRect(int index);
  void free(int index);
  void onUpdate(Part& part, int index, HasteFeature::Update update, std::size_t event_index);
  void recordHistory(TimeNs t_ns, int x, int y);

  HasteOptions options_;
  int width_;
  int height_;
  double half_;
  double border_px_;
  std::vector<Slot> slots_;
  std::vector<std::unique_ptr<Part>> parts_;           // slot s belongs to part s mod parts_.size()
  std::vector<std::vector<ChunkPoint>*> part_points_;  // each part's points, for the merge
  std::unique_ptr<WorkerPool> pool_;                   // null with one thread
  // Ring of the last history_events events (centred initialisation).
  std::vector<std::int32_t> history_x_, history_y_;
  std::vector<TimeNs> history_t_;
  std::size_t history_head_ = 0;
  std::size_t history_count_ = 0;
  TrackPoints out_;
  FeatureId next_id_ = 0;
  HasteCounters counters_;
};

}  // namespace evio::estimator

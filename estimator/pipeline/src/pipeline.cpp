#include "evio/estimator/pipeline/pipeline.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>

#include <opencv2/core/utility.hpp>

#include "evio/core/error.h"
#include "evio/core/slot_ring_thread.h"
#include "evio/core/stopwatch.h"
#include "evio/core/io/config.h"
#include "evio/core/io/images_txt.h"
#include "evio/estimator/pipeline/estimate_writer.h"
#include "evio/estimator/pipeline/method.h"
#include "evio/estimator/pipeline/sequence_rig.h"
#include "evio/estimator/pipeline/stages.h"
#include "stage_cpu_split.h"

namespace evio::estimator {

namespace {

namespace fs = std::filesystem;

/// The backend's initial covariance as standard deviations in SI units.
InitialErrorSigmas initialErrorSigmas(const BackendOptions& b) {
  constexpr double kDeg = M_PI / 180.0;
  return {b.initial_sigma_p_m, b.initial_sigma_v_mps, b.initial_sigma_theta_deg * kDeg,
          b.initial_sigma_bg_degps * kDeg, b.initial_sigma_ba_mps2};
}

/// Adds the wall time of its lifetime to a counter.
class StageTimer {
 public:
  explicit StageTimer(double* acc) : acc_(acc) {}
  ~StageTimer() { *acc_ += watch_.seconds(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double* acc_;
  Stopwatch watch_;
};

/// OpenCV's parallel loops (the frames' pyramids and filters, KLT) on at
/// most `threads` threads while it lives; with one, on the calling thread
/// alone (else an idle OpenCV worker spins between frames: 32 017
/// sched_yield calls in a 12 s EKLT-VIO run). Their results do not depend on
/// it. OpenCV's thread count is process-wide: runs in one process must not
/// overlap (runPipeline's contract, pipeline.h).
class OpenCvThreads {
 public:
  explicit OpenCvThreads(int threads) : previous_(cv::getNumThreads()) { cv::setNumThreads(threads > 1 ? threads : 0); }
  ~OpenCvThreads() { cv::setNumThreads(previous_); }
  OpenCvThreads(const OpenCvThreads&) = delete;
  OpenCvThreads& operator=(const OpenCvThreads&) = delete;

 private:
  int previous_;
};

/// Where the reading side stood after an item: what the backend side needs
/// to check health, write timing and progress, and the counts of the run if
/// it ends there.
struct ItemSnapshot {
  TimeNs t_now = 0;  // data time reached (camera clock)
  std::uint64_t events_read = 0;
  double fraction = 0.0;
  bool have_imu = false;
  TimeNs last_imu_cam = 0;
  PipelineCounts counts;  // events, events_kept, frames, track_points, imu_samples
};

/// The backend's share of one item: its inputs, and the snapshot after it.
struct BackendWork {
  std::vector<BackendInput> inputs;
  ItemSnapshot snapshot;
};

/// One run of the pipeline; see pipeline.h. setup() builds the stages once;
/// loop() reads the sequence and hands every item down the chain
/// (runStages), then checks the run's health and writes progress and timing.
class PipelineRun {
 public:
  PipelineRun(const std::string& sequence, const PipelineOptions& options, const std::string& output,
              const PipelineProgressCallback& progress)
      : sequence_(sequence), options_(options), output_(output), progress_(progress) {}

  PipelineResult run() {
    run_watch_.restart();
    run_start_cpu_s_ = Stopwatch::processCpuSeconds();
    setup();
    const OpenCvThreads opencv_threads(options_.frontend.threads);  // validated by setup()
    loop();
    finish();
    return result_;
  }

 private:
  void setup();
  void setupReader(const std::vector<io::ImageStamp>& images);
  void setupStages();
  void loop();
  /// The item through the reading side: `tracks`, or pre-filter, frontend
  /// and synchroniser; then its backend work goes to the backend side.
  void runFrontStages(SequenceItem& item, std::optional<SlotRingThread<BackendWork>>& handoff);
  /// At the end of the data: what the frontend still holds (a segment) goes
  /// through the synchroniser to the backend side.
  void finishFrontStages(std::optional<SlotRingThread<BackendWork>>& handoff);
  /// The frontend's outputs (tracked_) through the synchroniser, and to the
  /// backend side one work per input, each with the snapshot taken when its
  /// input was read: inputs held in a segment reach the backend side exactly
  /// as they would have one by one.
  void releaseTracked(std::optional<SlotRingThread<BackendWork>>& handoff);
  void handOn(BackendWork& work, std::optional<SlotRingThread<BackendWork>>& handoff);
  void takeSnapshot(ItemSnapshot& snapshot) const;
  void consume(BackendWork& work);
  void afterItem(const ItemSnapshot& snapshot);
  void closeBackend();
  void writeTiming(TimeNs t_ns, std::uint64_t events_read);
  void finish();
  io::EstimateStatus finalStatus() const;
  /// timing.txt's features: those of the latest measurement set the backend
  /// side took (the same for any frontend.threads and backend_thread).
  std::int64_t trackedFeatures() const { return static_cast<std::int64_t>(backend_stage_->lastSetFeatures()); }
  /// Processing time since the loop started on the clock of output.timing_clock.
  double elapsed() const {
    return cpu_clock_ ? Stopwatch::processCpuSeconds() - loop_start_cpu_s_ : loop_watch_.seconds();
  }

  const std::string& sequence_;
  PipelineOptions options_;  // a copy: setup() fills in the sensor-dependent frontend options
  const std::string& output_;
  const PipelineProgressCallback& progress_;
  PipelineResult result_;
  Method method_ = Method::kEkltVio;

  SequenceRig rig_;
  const CameraSensor* tracker_camera_ = nullptr;
  cv::Size frame_size_;
  std::string frame_size_from_;
  TimeNs offset_ns_ = 0;

  // The chain, in the order data flows (stages.h).
  std::unique_ptr<SequenceReader> reader_;
  std::unique_ptr<PrefilterStage> prefilter_;
  std::unique_ptr<FrontendStage> frontend_;
  std::unique_ptr<SynchronizerStage> sync_;
  std::unique_ptr<TracksStage> tracks_;  // replaces prefilter, frontend and synchroniser for `tracks`
  std::unique_ptr<Backend> backend_;
  std::unique_ptr<BackendStage> backend_stage_;
  std::unique_ptr<HealthMonitor> health_;
  std::unique_ptr<EstimateWriter> writer_;
  // Each stage's outputs, reused from item to item.
  std::vector<SequenceItem> filtered_;
  std::vector<FrontendOutput> tracked_;
  std::vector<std::vector<BackendInput>> synced_;  // the synchroniser's outputs per entry of tracked_
  std::deque<ItemSnapshot> snapshots_;  // of the inputs whose frontend outputs are still to come (a segment)
  BackendWork inline_work_;  // without a backend thread
  std::vector<Estimate> estimates_;
  std::vector<Estimate> checked_;
  // stage_cpu_s: one split per thread (the reading thread's also takes the
  // backend side without a backend thread).
  StageCpuSplit reading_cpu_;
  StageCpuSplit backend_thread_cpu_;

  // Loop state
  Stopwatch run_watch_;
  double run_start_cpu_s_ = 0.0;
  Stopwatch loop_watch_;
  double loop_start_cpu_s_ = 0.0;
  bool cpu_clock_ = false;
  bool have_imu_ = false;
  TimeNs last_imu_cam_ = 0;
  bool timing_started_ = false;
  TimeNs last_timing_t_ = 0;
  TimeNs t_now_ = 0;
  bool any_item_ = false;
  std::optional<io::EstimateStatus> pipeline_failure_;
  // Backend side (the backend thread when options.backend_thread)
  std::atomic<bool> stopped_{false};  // diverged or failed with stop_on_divergence: no more input
  ItemSnapshot last_consumed_;        // the last item the backend side took
};

void PipelineRun::setup() {
  StageTimer timer(&result_.times.setup_s);
  options_.validate();
  if (!fs::is_directory(sequence_)) throw Error(sequence_ + ": not a folder");
  method_ = options_.methodKind();
  const MethodInfo& method = methodInfo(method_);
  // Event trackers seeded on frames: EKLT and HASTE.
  const bool eklt = method_ == Method::kEkltVio || method_ == Method::kHasteVio;

  // Frames: needed by KLT and by EKLT on sensor frames; fused into the reconstruction when present.
  const bool has_images = fs::exists(fs::path(sequence_) / "images.txt");
  const std::vector<io::ImageStamp> images = has_images ? io::readImageList(sequence_) : std::vector<io::ImageStamp>{};
  const bool frames_needed = method_ == Method::kKltVio || (eklt && options_.frontend.image_source == "frames");
  if (frames_needed && images.empty())
    throw Error(sequence_ + ": no frames (images.txt " + (has_images ? "is empty" : "missing") + ") for " +
                options_.method + (eklt ? "; to track on frames reconstructed from events, run with "
                                          "--set frontend.image_source=reconstructed"
                                        : "; KLT-VIO needs frames"));
  std::optional<cv::Size> first_frame_size;
  if (!images.empty()) first_frame_size = io::readFrame(sequence_, images.front()).size();

  rig_ = loadSequenceRig(sequence_, options_.calibration, options_.backend, first_frame_size);
  result_.rig_source = rig_.source;
  offset_ns_ = rig_.rig.time_offset_cam_imu_ns;
  const CameraSensor& event_cam = rig_.eventCamera();
  tracker_camera_ = method.tracks_frame_camera ? &rig_.frameCamera() : &event_cam;
  result_.tracker_camera = tracker_camera_->name;
  options_.frontend = resolveSensorParameters(options_.frontend, event_cam.parameters);  // config.yaml shows them
  if (method.tracks_frame_camera && tracker_camera_ == &event_cam && rig_.source == "sensors.yaml" &&
      rig_.rig.cameras.size() > 1)
    result_.notes.push_back(options_.method + ": no frame camera in sensors.yaml; using the event camera's calibration");
  // Frames go to the tracker camera (EKLT: the event camera, the DAVIS frames share its pixels).
  const Camera& fc = tracker_camera_->camera;
  frame_size_ = cv::Size(fc.width(), fc.height());
  frame_size_from_ = rig_.describe(*tracker_camera_);
  if (first_frame_size && method_ != Method::kTracks && *first_frame_size != frame_size_)
    throw Error((fs::path(sequence_) / images.front().relative_path).string() + ": frame size " +
                std::to_string(first_frame_size->width) + "x" + std::to_string(first_frame_size->height) +
                " differs from " + frame_size_from_ + " (" + std::to_string(frame_size_.width) + "x" +
                std::to_string(frame_size_.height) + ")");
  setupReader(images);
  setupStages();
  writer_ = std::make_unique<EstimateWriter>(output_, options_.output, event_cam.T_B_C, offset_ns_,
                                             std::vector<std::string>{"evio estimate " + sequence_ + " (" +
                                                                      options_.method + ")"});
}

void PipelineRun::setupReader(const std::vector<io::ImageStamp>& images) {
  const CameraSensor& event_cam = rig_.eventCamera();
  SequenceReaderOptions ro;
  ro.read_events = methodInfo(method_).reads_events;
  ro.read_frames = method_ != Method::kTracks && !images.empty();
  ro.read_imu = true;
  ro.read_range = options_.backend.use_range;
  if (options_.backend.use_range && !rig_.rig.range_finder)
    throw Error("backend.use_range: " + rig_.source + " of " + sequence_ + " has no range finder");
  if (options_.backend.use_range && !fs::exists(fs::path(sequence_) / "range.txt"))
    throw Error("backend.use_range: " + (fs::path(sequence_) / "range.txt").string() + " not found");
  ro.event_width = event_cam.camera.width();
  ro.event_height = event_cam.camera.height();
  ro.calibration = rig_.describe(event_cam);
  ro.time_offset_cam_imu_ns = offset_ns_;
  reader_ = std::make_unique<SequenceReader>(sequence_, ro);
  result_.events_file = reader_->eventsFile();
}

void PipelineRun::setupStages() {
  if (method_ == Method::kTracks) {
    fs::path file(options_.tracks.file);
    if (file.is_relative()) file = fs::path(sequence_) / file;
    if (!fs::exists(file)) throw Error(file.string() + ": tracks file not found (tracks.file)");
    auto input = std::make_unique<TracksInput>(file.string(), options_.tracks, options_.seed);
    result_.notes.push_back("tracks: " + std::to_string(input->numSamples()) + " samples of " +
                            std::to_string(input->numTracks()) + " tracks (" + std::to_string(input->numSplits()) +
                            " split at gaps above tracks.max_gap_s)");
    tracks_ = std::make_unique<TracksStage>(std::move(input));
  } else {
    prefilter_ = std::make_unique<PrefilterStage>(options_.frontend.prefilter, tracker_camera_->camera.width(),
                                                  tracker_camera_->camera.height());
    // The frames' word on rest for the window's still test (still_frame_probe.h).
    const InitOptions& init = options_.init;
    const bool still_test = init.gyro_bias_window_s > 0.0 && init.gyro_bias_window_rest &&
                            init.gyro_bias_window_rest_prefix_s > 0.0;
    const double still_probe_s = still_test ? init.start_offset_s + init.gyro_bias_window_s : 0.0;
    frontend_ = std::make_unique<FrontendStage>(options_.frontend, *tracker_camera_, still_probe_s);
    sync_ = std::make_unique<SynchronizerStage>(options_.sync);
  }
  backend_ = std::make_unique<Backend>(options_.backend, BackendSensors::fromRig(rig_.rig, tracker_camera_->name));
  std::optional<GroundTruthInitializer> initializer;
  if (options_.init.mode == "groundtruth") {
    const std::string groundtruth = (fs::path(sequence_) / "groundtruth.txt").string();
    if (!fs::exists(groundtruth))
      throw Error(sequence_ + ": no groundtruth.txt for --init groundtruth; run with --init static");
    initializer.emplace(groundtruth, options_.init.start_offset_s, options_.init.velocity_half_window_s,
                        rig_.eventCamera().T_B_C, offset_ns_);
    if (options_.init.perturb) {
      initializer->perturbWith(initialErrorSigmas(options_.backend), options_.seed);
      result_.notes.push_back("initial state: the ground truth plus an error drawn from the initial covariance "
                              "(init.perturb, seed " + std::to_string(options_.seed) + ")");
    }
  } else {
    result_.notes.push_back("static initialisation: position and yaw zero, the estimate needs alignment");
  }
  std::optional<GyroBiasWindow> gyro_bias_window;
  if (options_.init.gyro_bias_window_s > 0.0) {
    WindowRestTest rest;
    rest.enabled = options_.init.gyro_bias_window_rest;
    rest.gravity_mps2 = rig_.rig.gravity_m_s2;
    rest.max_acc_std_mps2 = options_.backend.static_max_acc_std_mps2;
    rest.max_gyro_std_radps = options_.backend.static_max_gyro_std_radps;
    rest.noise = options_.backend.imuNoise(rig_.rig.imu);
    rest.prefix.min_s = options_.init.gyro_bias_window_rest_prefix_s;
    rest.prefix.block_s = options_.init.gyro_bias_window_rest_block_s;
    if (method_ == Method::kTracks) rest.still_track_sigma_px = std::max(0.1, options_.tracks.noise_px);
    gyro_bias_window.emplace(options_.init.gyro_bias_window_s, options_.init.gyro_bias_keyframe_s,
                             tracker_camera_->camera, tracker_camera_->T_B_C.rotation(), offset_ns_, rest);
    gyro_bias_window->setTracksOnce(options_.init.gyro_bias_window_tracks_once);
    gyro_bias_window->setReplayWithWindowSigma(options_.init.gyro_bias_window_sigma == "window");
  }
  backend_stage_ = std::make_unique<BackendStage>(*backend_, std::move(initializer), std::move(gyro_bias_window));
  health_ = std::make_unique<HealthMonitor>(options_.health);
}

void PipelineRun::runFrontStages(SequenceItem& item, std::optional<SlotRingThread<BackendWork>>& handoff) {
  PipelineStageCpu& cpu = result_.cpu;
  StageCpuSplit& split = reading_cpu_;
  if (tracks_) {
    BackendWork& work = handoff ? handoff->slot() : inline_work_;
    work.inputs.clear();
    split.begin();
    {
      StageTimer timer(&result_.times.frontend_s);
      tracks_->process(item, work.inputs);
    }
    split.lap(&cpu.sync_s);
    takeSnapshot(work.snapshot);
    handOn(work, handoff);
    return;
  }
  split.begin();
  {
    StageTimer timer(&result_.times.frontend_s);
    filtered_.clear();
    tracked_.clear();
    prefilter_->process(item, filtered_);
    split.lap(&cpu.prefilter_s);
    // The tracker's wait for its worker threads uses no CPU of this thread.
    const double waited0 = frontend_->trackerParallelCpu().wait_s;
    for (SequenceItem& f : filtered_) frontend_->process(f, tracked_);
    split.lap(&cpu.tracking_s, frontend_->trackerParallelCpu().wait_s - waited0);
    if (!filtered_.empty()) std::swap(item, filtered_.front());  // the reader keeps its buffers
  }
  takeSnapshot(snapshots_.emplace_back());
  releaseTracked(handoff);
}

void PipelineRun::finishFrontStages(std::optional<SlotRingThread<BackendWork>>& handoff) {
  if (!frontend_ || !frontend_->holding()) return;
  PipelineStageCpu& cpu = result_.cpu;
  StageCpuSplit& split = reading_cpu_;
  split.begin();
  {
    StageTimer timer(&result_.times.frontend_s);
    tracked_.clear();
    const double waited0 = frontend_->trackerParallelCpu().wait_s;
    frontend_->finish(tracked_);
    split.lap(&cpu.tracking_s, frontend_->trackerParallelCpu().wait_s - waited0);
  }
  releaseTracked(handoff);
}

void PipelineRun::releaseTracked(std::optional<SlotRingThread<BackendWork>>& handoff) {
  PipelineStageCpu& cpu = result_.cpu;
  StageCpuSplit& split = reading_cpu_;
  // Every input gives the frontend stage exactly one output, in input order.
  require(tracked_.size() <= snapshots_.size(), "pipeline: the frontend released more outputs than it took inputs");
  if (synced_.size() < tracked_.size()) synced_.resize(tracked_.size());
  {
    StageTimer timer(&result_.times.frontend_s);
    for (std::size_t k = 0; k < tracked_.size(); ++k) {
      synced_[k].clear();
      sync_->process(tracked_[k], synced_[k]);
      snapshots_[k].counts.track_points = sync_->numTrackPoints();
    }
  }
  split.lap(&cpu.sync_s);
  for (std::size_t k = 0; k < tracked_.size(); ++k) {
    BackendWork& work = handoff ? handoff->slot() : inline_work_;
    std::swap(work.inputs, synced_[k]);
    work.snapshot = snapshots_.front();
    snapshots_.pop_front();
    handOn(work, handoff);
  }
}

void PipelineRun::handOn(BackendWork& work, std::optional<SlotRingThread<BackendWork>>& handoff) {
  if (handoff)
    handoff->push();
  else
    consume(work);
}

void PipelineRun::takeSnapshot(ItemSnapshot& s) const {
  s.t_now = t_now_;
  s.events_read = reader_->eventsRead();
  s.fraction = reader_->fraction();
  s.have_imu = have_imu_;
  s.last_imu_cam = last_imu_cam_;
  s.counts.imu_samples = result_.counts.imu_samples;
  if (prefilter_) {
    s.counts.events = prefilter_->numEventsSeen();
    s.counts.events_kept = prefilter_->numEventsKept();
    s.counts.frames = frontend_->numFrames();
    s.counts.track_points = sync_->numTrackPoints();
  }
}

/// The backend side of one item: backend, health monitor, writer, then the
/// run's health checks, timing and progress. Nothing once stopped.
void PipelineRun::consume(BackendWork& work) {
  if (stopped_.load(std::memory_order_relaxed)) return;
  PipelineStageCpu& cpu = result_.cpu;
  StageCpuSplit& split = options_.backend_thread ? backend_thread_cpu_ : reading_cpu_;
  split.begin();
  estimates_.clear();
  {
    StageTimer timer(&result_.times.backend_s);
    for (BackendInput& in : work.inputs) backend_stage_->process(in, estimates_);
  }
  split.lap(&cpu.backend_s);
  checked_.clear();
  for (Estimate& e : estimates_) health_->process(e, checked_);
  {
    StageTimer timer(&result_.times.output_s);
    for (const Estimate& e : checked_) writer_->addEstimate(e);
  }
  afterItem(work.snapshot);
  split.lap(&cpu.output_s);
  last_consumed_ = work.snapshot;
  const bool stop = !backend_->status().ok() || pipeline_failure_.has_value();
  if (stop && options_.output.stop_on_divergence) stopped_.store(true);
}

/// After the last item (the backend thread, if any, has stopped): what the
/// backend stage still holds (an open gyroscope-bias window) goes through.
void PipelineRun::closeBackend() {
  if (stopped_.load(std::memory_order_relaxed)) return;
  estimates_.clear();
  {
    StageTimer timer(&result_.times.backend_s);
    backend_stage_->finish(estimates_);
  }
  checked_.clear();
  for (Estimate& e : estimates_) health_->process(e, checked_);
  StageTimer timer(&result_.times.output_s);
  for (const Estimate& e : checked_) writer_->addEstimate(e);
  if (backend_->initialized() && !result_.initialization_t_ns)
    result_.initialization_t_ns = backend_->initializedAt() - offset_ns_;
}

void PipelineRun::afterItem(const ItemSnapshot& snapshot) {
  const TimeNs t_ns = snapshot.t_now;
  if (backend_->initialized() && !result_.initialization_t_ns)
    result_.initialization_t_ns = backend_->initializedAt() - offset_ns_;
  // The IMU must keep up with the other streams: a run of data without IMU
  // longer than imu_fail_gap_s after initialisation fails like a gap.
  if (backend_->initialized() && backend_->status().ok() && snapshot.have_imu && !pipeline_failure_ &&
      nsToSeconds(t_ns - snapshot.last_imu_cam) > options_.backend.imu_fail_gap_s) {
    io::EstimateStatus s;
    s.code = io::EstimateStatus::Code::kFailed;
    s.t_ns = snapshot.last_imu_cam;
    s.cause = "no IMU reading after " + secondsText(snapshot.last_imu_cam) + " while data continue (gap above " +
              "backend.imu_fail_gap_s)";
    pipeline_failure_ = s;
  }
  if (result_.initialization_t_ns) writeTiming(t_ns, snapshot.events_read);
  if (progress_) progress_(PipelineProgress{snapshot.fraction, t_ns, snapshot.events_read, backend_->initialized()});
}

void PipelineRun::writeTiming(TimeNs t_ns, std::uint64_t events_read) {
  if (timing_started_ && !(t_ns > last_timing_t_ && nsToSeconds(t_ns - last_timing_t_) >= options_.output.timing_interval_s))
    return;
  const TimeNs t = timing_started_ ? t_ns : std::max(t_ns, *result_.initialization_t_ns);
  if (timing_started_ && t <= last_timing_t_) return;
  const double processing = elapsed();  // read only when written: on the CPU clock it is a system call
  writer_->addTiming(io::TimingSample{t, processing, static_cast<std::int64_t>(events_read), trackedFeatures()});
  timing_started_ = true;
  last_timing_t_ = t;
}

void PipelineRun::loop() {
  loop_watch_.restart();
  loop_start_cpu_s_ = Stopwatch::processCpuSeconds();
  cpu_clock_ = options_.output.timing_clock == "cpu";
  // With a backend thread, items wait in a ring of 64 between the two sides.
  // Destroyed while an error unwinds, it still consumes what was queued: the
  // backend takes every item read before the error, as on one thread.
  std::optional<SlotRingThread<BackendWork>> handoff;
  if (options_.backend_thread)
    handoff.emplace(64, [this](BackendWork& w) { consume(w); }, SlotRingThread<BackendWork>::OnDestroy::kConsumeQueued);
  SequenceItem item;
  while (!stopped_.load() && !(handoff && handoff->failed())) {
    {
      StageTimer timer(&result_.times.read_s);
      reading_cpu_.begin();
      const bool more = reader_->next(item);
      if (more && item.kind == SequenceItem::Kind::kFrame)
        item.image = reader_->loadFrame(item.frame_index, frame_size_, frame_size_from_);
      reading_cpu_.lap(&result_.cpu.read_s);
      if (!more) break;
    }
    if (!any_item_) {
      result_.t_first_ns = item.kind == SequenceItem::Kind::kEvents ? item.events.t().front() : item.t_ns;
      any_item_ = true;
    }
    t_now_ = std::max(t_now_, item.t_ns);
    if (item.kind == SequenceItem::Kind::kImu) {
      ++result_.counts.imu_samples;
      have_imu_ = true;
      last_imu_cam_ = item.t_ns;
    }
    runFrontStages(item, handoff);
  }
  if (!stopped_.load() && !(handoff && handoff->failed())) finishFrontStages(handoff);
  if (handoff) handoff->finish();
  closeBackend();
  reading_cpu_.flush();
  backend_thread_cpu_.flushByWall();  // the backend thread has stopped
  // The run ends at the last item the backend side took (the same item
  // whether or not it ran on its own thread).
  result_.t_last_ns = last_consumed_.t_now;
  result_.counts.imu_samples = last_consumed_.counts.imu_samples;
  if (prefilter_) {
    result_.counts.events = last_consumed_.counts.events;
    result_.counts.events_kept = last_consumed_.counts.events_kept;
    result_.counts.frames = last_consumed_.counts.frames;
    result_.counts.track_points = last_consumed_.counts.track_points;
    const WorkerPool::Cpu parallel = frontend_->trackerParallelCpu();
    result_.cpu.tracking_s += parallel.workers_s;
    result_.cpu.tracking_workers_s = parallel.workers_s;
    result_.cpu.tracking_critical_path_s = result_.cpu.tracking_s - parallel.parts_s + parallel.critical_path_s;
    if (const EkltTiming* t = frontend_->ekltTiming()) {
      result_.cpu.eklt_optimisation_s = t->optimisation_s;
      result_.cpu.eklt_events_s = t->splattingS();
      result_.cpu.eklt_frames_s = t->frame_s;
      result_.eklt = EkltSolverCounts{t->events_in_patches, t->optimisations, t->solver_iterations,
                                      t->reversal_solves, t->batches_dropped};
    }
    result_.track_lag = frontend_->trackLag();
  }
  result_.counts.measurement_sets = backend_stage_->numMeasurementSets();
  result_.gyro_bias = backend_stage_->gyroBiasEstimate();
}

io::EstimateStatus PipelineRun::finalStatus() const {
  io::EstimateStatus status;
  const BackendStatus& bs = backend_->status();
  if (!bs.ok()) {
    status.code = bs.code;
    status.t_ns = bs.t_ns - offset_ns_;
    status.cause = bs.cause;
  } else if (pipeline_failure_) {
    status = *pipeline_failure_;
  } else if (health_->verdict().code != io::EstimateStatus::Code::kOk) {
    const HealthVerdict& v = health_->verdict();
    status.code = v.code;
    status.t_ns = v.t_ns - offset_ns_;
    status.cause = v.cause;
  } else if (!backend_->initialized()) {
    status.code = io::EstimateStatus::Code::kFailed;
    status.t_ns = last_consumed_.t_now;
    status.cause = options_.init.mode == "static"
                       ? "never initialised: no still IMU window of backend.static_window_s"
                       : "never initialised: no IMU reading at or after the initialisation time";
  }
  status.initialization_t_ns = result_.initialization_t_ns;
  return status;
}

void PipelineRun::finish() {
  if (timing_started_ && last_consumed_.t_now > last_timing_t_)
    writer_->addTiming(io::TimingSample{last_consumed_.t_now, elapsed(),
                                        static_cast<std::int64_t>(last_consumed_.events_read), trackedFeatures()});
  result_.backend = backend_->stats();
  result_.counts.poses = writer_->numPoses();
  result_.status = finalStatus();
  {
    StageTimer timer(&result_.times.output_s);
    result_.times.total_s = run_watch_.seconds();
    result_.times.cpu_s = Stopwatch::processCpuSeconds() - run_start_cpu_s_;
    writer_->finish(result_.status, config::toYaml(options_), formatPipelineSummary(result_, options_));
  }
  result_.times.total_s = run_watch_.seconds();
  result_.times.cpu_s = Stopwatch::processCpuSeconds() - run_start_cpu_s_;
}

}  // namespace

PipelineResult runPipeline(const std::string& sequence, const PipelineOptions& options, const std::string& output,
                           const PipelineProgressCallback& progress) {
  PipelineRun run(sequence, options, output, progress);
  return run.run();
}

}  // namespace evio::estimator

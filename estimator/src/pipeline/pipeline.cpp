#include "evio/estimator/pipeline/pipeline.h"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <memory>

#include "evio/core/error.h"
#include "evio/core/io/config.h"
#include "evio/core/io/images_txt.h"
#include "evio/estimator/backend/backend.h"
#include "evio/estimator/frontend/frontend.h"
#include "evio/estimator/pipeline/estimate_writer.h"
#include "evio/estimator/pipeline/groundtruth_init.h"
#include "evio/estimator/pipeline/sequence_reader.h"
#include "evio/estimator/pipeline/sequence_rig.h"
#include "evio/estimator/pipeline/tracks_input.h"

namespace evio::estimator {

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string secondsText(TimeNs t_ns) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.3f s", nsToSeconds(t_ns));
  return buf;
}

/// Adds the wall time of its lifetime to a counter.
class StageTimer {
 public:
  explicit StageTimer(double* acc) : acc_(acc), start_(Clock::now()) {}
  ~StageTimer() { *acc_ += std::chrono::duration<double>(Clock::now() - start_).count(); }
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

 private:
  double* acc_;
  Clock::time_point start_;
};

io::EstimateStatus::Code statusCode(BackendStatus::Code c) {
  switch (c) {
    case BackendStatus::Code::kOk: return io::EstimateStatus::Code::kOk;
    case BackendStatus::Code::kDiverged: return io::EstimateStatus::Code::kDiverged;
    case BackendStatus::Code::kFailed: return io::EstimateStatus::Code::kFailed;
  }
  return io::EstimateStatus::Code::kFailed;
}

/// One run of the pipeline; see pipeline.h.
class PipelineRun {
 public:
  PipelineRun(const std::string& sequence, const PipelineOptions& options, const std::string& output,
              const PipelineProgressCallback& progress)
      : sequence_(sequence), options_(options), output_(output), progress_(progress) {}

  PipelineResult run() {
    run_start_ = Clock::now();
    run_start_cpu_ = std::clock();
    setup();
    loop();
    finish();
    return result_;
  }

 private:
  void setup();
  void setupInitialization();
  void loop();
  void finish();
  void onImu(const SequenceItem& item);
  void onRange(const SequenceItem& item);
  void onEvents(const SequenceItem& item);
  void onFrame(const SequenceItem& item);
  void collectTracks();
  void feedSets(std::vector<MeasurementSet>& sets);
  void afterItem(TimeNs t_ns);
  /// Processing time since the loop started on the clock of output.timing_clock.
  double elapsed() const {
    if (cpu_clock_) return static_cast<double>(std::clock() - loop_start_cpu_) / CLOCKS_PER_SEC;
    return std::chrono::duration<double>(Clock::now() - loop_start_).count();
  }

  const std::string& sequence_;
  const PipelineOptions& options_;
  const std::string& output_;
  const PipelineProgressCallback& progress_;
  PipelineResult result_;

  bool eklt_ = false, klt_ = false, tracks_ = false;
  SequenceRig rig_;
  const CameraSensor* tracker_camera_ = nullptr;
  std::unique_ptr<SequenceReader> reader_;
  std::unique_ptr<Frontend> frontend_;
  std::unique_ptr<Synchronizer> sync_;
  std::unique_ptr<TracksInput> tracks_input_;
  std::unique_ptr<Backend> backend_;
  std::unique_ptr<EstimateWriter> writer_;
  cv::Size frame_size_;
  std::string frame_size_from_;
  TimeNs offset_ns_ = 0;

  // Initialisation
  std::string init_mode_;
  std::string groundtruth_;
  bool init_time_known_ = false;
  TimeNs init_t_cam_ = 0;

  // Loop state
  Clock::time_point run_start_;
  std::clock_t run_start_cpu_ = 0;
  Clock::time_point loop_start_;
  std::clock_t loop_start_cpu_ = 0;
  bool cpu_clock_ = false;
  TrackPoints points_;
  std::vector<MeasurementSet> sets_;
  bool have_imu_ = false;
  TimeNs last_imu_cam_ = 0;
  bool timing_started_ = false;
  TimeNs last_timing_t_ = 0;
  TimeNs t_now_ = 0;
  bool any_item_ = false;
  std::optional<io::EstimateStatus> pipeline_failure_;
};

void PipelineRun::setup() {
  StageTimer timer(&result_.times.setup_s);
  options_.validate();
  if (!fs::is_directory(sequence_)) throw Error(sequence_ + ": not a folder");
  eklt_ = options_.method == "eklt-vio";
  klt_ = options_.method == "klt-vio";
  tracks_ = options_.method == "tracks";

  // Frames: needed by KLT and by EKLT on sensor frames; fused into the reconstruction when present.
  const bool has_images = fs::exists(fs::path(sequence_) / "images.txt");
  const std::vector<io::ImageStamp> images = has_images ? io::readImageList(sequence_) : std::vector<io::ImageStamp>{};
  const bool frames_needed = klt_ || (eklt_ && options_.frontend.image_source == "frames");
  if (frames_needed && images.empty())
    throw Error(sequence_ + ": no frames (images.txt " + (has_images ? "is empty" : "missing") + ") for " +
                options_.method + (eklt_ ? "; to track on frames reconstructed from events, run with "
                                           "--set frontend.image_source=reconstructed"
                                         : "; KLT-VIO needs frames"));
  std::optional<cv::Size> first_frame_size;
  if (!images.empty()) first_frame_size = io::readFrame(sequence_, images.front()).size();

  rig_ = loadSequenceRig(sequence_, options_.calibration, options_.backend, first_frame_size);
  result_.rig_source = rig_.source;
  offset_ns_ = rig_.rig.time_offset_cam_imu_ns;
  const CameraSensor& event_cam = rig_.eventCamera();
  tracker_camera_ = klt_ ? &rig_.frameCamera() : &event_cam;
  result_.tracker_camera = tracker_camera_->name;
  if (klt_ && tracker_camera_ == &event_cam && rig_.source == "sensors.yaml" && rig_.rig.cameras.size() > 1)
    result_.notes.push_back("klt-vio: no frame camera in sensors.yaml; using the event camera's calibration");
  // Frames go to the tracker camera (EKLT: the event camera, the DAVIS frames share its pixels).
  const Camera& fc = tracker_camera_->camera;
  frame_size_ = cv::Size(fc.width(), fc.height());
  frame_size_from_ = rig_.describe(*tracker_camera_);
  if (first_frame_size && !tracks_ && *first_frame_size != frame_size_)
    throw Error((fs::path(sequence_) / images.front().relative_path).string() + ": frame size " +
                std::to_string(first_frame_size->width) + "x" + std::to_string(first_frame_size->height) +
                " differs from " + frame_size_from_ + " (" + std::to_string(frame_size_.width) + "x" +
                std::to_string(frame_size_.height) + ")");

  SequenceReaderOptions ro;
  ro.read_events = eklt_;
  ro.read_frames = (eklt_ || klt_) && !images.empty();
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

  if (eklt_ || klt_) {
    frontend_ = std::make_unique<Frontend>(options_.frontend, tracker_camera_->camera, tracker_camera_->T_B_C);
    sync_ = std::make_unique<Synchronizer>(options_.sync);
  } else {
    fs::path file(options_.tracks.file);
    if (file.is_relative()) file = fs::path(sequence_) / file;
    if (!fs::exists(file)) throw Error(file.string() + ": tracks file not found (tracks.file)");
    tracks_input_ = std::make_unique<TracksInput>(file.string(), options_.tracks, options_.seed);
    result_.notes.push_back("tracks: " + std::to_string(tracks_input_->numSamples()) + " samples of " +
                            std::to_string(tracks_input_->numTracks()) + " tracks (" +
                            std::to_string(tracks_input_->numSplits()) + " split at gaps above tracks.max_gap_s)");
  }
  backend_ = std::make_unique<Backend>(options_.backend, BackendSensors::fromRig(rig_.rig, tracker_camera_->name));
  setupInitialization();

  writer_ = std::make_unique<EstimateWriter>(output_, options_.output, event_cam.T_B_C, offset_ns_,
                                             std::vector<std::string>{"evio estimate " + sequence_ + " (" +
                                                                      options_.method + ")"});
}

void PipelineRun::setupInitialization() {
  groundtruth_ = (fs::path(sequence_) / "groundtruth.txt").string();
  const bool has_gt = fs::exists(groundtruth_);
  init_mode_ = options_.init.mode;
  if (init_mode_ == "auto") init_mode_ = has_gt ? "groundtruth" : "static";
  if (init_mode_ == "groundtruth" && !has_gt)
    throw Error(sequence_ + ": no groundtruth.txt for init.mode groundtruth; run with --set init.mode=static");
  if (init_mode_ == "static") {
    backend_->setAutoStaticInitialization(true);
    result_.notes.push_back("static initialisation: position and yaw zero, the estimate needs alignment");
  }
}

void PipelineRun::collectTracks() {
  points_.clear();
  frontend_->drainTrackPoints(points_);
  if (points_.empty()) return;
  result_.track_points += points_.size();
  sync_->addTrackPoints(points_);
}

void PipelineRun::feedSets(std::vector<MeasurementSet>& sets) {
  StageTimer timer(&result_.times.backend_s);
  for (const MeasurementSet& s : sets) {
    backend_->addMeasurementSet(s);
    ++result_.measurement_sets;
  }
  sets.clear();
}

void PipelineRun::onImu(const SequenceItem& item) {
  ++result_.imu_samples;
  have_imu_ = true;
  last_imu_cam_ = item.t_ns;
  if (init_mode_ == "groundtruth" && !backend_->initialized()) {
    if (!init_time_known_) {
      StageTimer timer(&result_.times.setup_s);
      const Trajectory head = readTrajectoryPrefix(groundtruth_, item.t_ns);
      if (head.empty()) throw Error(groundtruth_ + ": no poses");
      init_t_cam_ = std::max(item.t_ns, head.front().t_ns) + secondsToNs(options_.init.start_offset_s);
      init_time_known_ = true;
    }
    if (item.t_ns >= init_t_cam_) {
      StageTimer timer(&result_.times.setup_s);
      const double h = options_.init.velocity_half_window_s;
      const Trajectory gt = readTrajectoryPrefix(groundtruth_, init_t_cam_ + secondsToNs(h));
      if (gt.back().t_ns < init_t_cam_)
        throw Error(groundtruth_ + ": ends at " + secondsText(gt.back().t_ns) + ", before the initialisation time " +
                    secondsText(init_t_cam_));
      backend_->initialize(
          initialStateFromTrajectory(gt, init_t_cam_, rig_.eventCamera().T_B_C, h, offset_ns_));
    }
  }
  if (frontend_) {
    StageTimer timer(&result_.times.frontend_s);
    ImuSample cam_clock = item.imu;
    cam_clock.t_ns = item.t_ns;
    frontend_->addImu(cam_clock);
    sync_->advanceTime(item.t_ns);
  }
  {
    StageTimer timer(&result_.times.backend_s);
    backend_->addImu(item.imu);
  }
  if (tracks_input_) {
    {
      StageTimer timer(&result_.times.frontend_s);
      tracks_input_->advanceTo(item.t_ns, sets_);
    }
    feedSets(sets_);
  }
}

void PipelineRun::onRange(const SequenceItem& item) {
  if (!item.range.valid) return;  // no return: nothing measured
  StageTimer timer(&result_.times.backend_s);
  backend_->addRange(item.t_ns, item.range.range_m);
}

void PipelineRun::onEvents(const SequenceItem& item) {
  StageTimer timer(&result_.times.frontend_s);
  const std::uint64_t kept_before = frontend_->numEventsKept();
  frontend_->addEvents(item.events);
  collectTracks();
  sync_->addEvents(frontend_->numEventsKept() - kept_before, item.t_ns);
}

void PipelineRun::onFrame(const SequenceItem& item) {
  cv::Mat image;
  {
    StageTimer timer(&result_.times.read_s);
    image = reader_->loadFrame(item.frame_index, frame_size_, frame_size_from_);
  }
  StageTimer timer(&result_.times.frontend_s);
  frontend_->addFrame(item.t_ns, image);
  ++result_.frames;
  collectTracks();
  sync_->advanceTime(item.t_ns);
}

void PipelineRun::afterItem(TimeNs t_ns) {
  if (sync_) {
    MeasurementSet set;
    while (sync_->poll(&set)) sets_.push_back(std::move(set));
    feedSets(sets_);
  }
  {
    StageTimer timer(&result_.times.output_s);
    for (const BackendEstimate& e : backend_->takeEstimates()) writer_->addEstimate(e);
  }
  if (backend_->initialized() && !result_.initialization_t_ns)
    result_.initialization_t_ns = backend_->state().imu.t_ns - offset_ns_;
  // The IMU must keep up with the other streams: a run of data without IMU
  // longer than imu_fail_gap_s after initialisation fails like a gap.
  if (backend_->initialized() && backend_->status().ok() && have_imu_ && !pipeline_failure_ &&
      nsToSeconds(t_ns - last_imu_cam_) > options_.backend.imu_fail_gap_s) {
    io::EstimateStatus s;
    s.code = io::EstimateStatus::Code::kFailed;
    s.t_ns = last_imu_cam_;
    s.cause = "no IMU reading after " + secondsText(last_imu_cam_) + " while data continue (gap above " +
              "backend.imu_fail_gap_s)";
    pipeline_failure_ = s;
  }
  if (result_.initialization_t_ns) {
    const double processing = elapsed();
    if (!timing_started_ || (t_ns > last_timing_t_ && nsToSeconds(t_ns - last_timing_t_) >= options_.output.timing_interval_s)) {
      const TimeNs t = timing_started_ ? t_ns : std::max(t_ns, *result_.initialization_t_ns);
      if (!timing_started_ || t > last_timing_t_) {
        writer_->addTiming(io::TimingSample{t, processing, static_cast<std::int64_t>(reader_->eventsRead())});
        timing_started_ = true;
        last_timing_t_ = t;
      }
    }
  }
  if (progress_)
    progress_(PipelineProgress{reader_->fraction(), t_ns, reader_->eventsRead(), backend_->initialized()});
}

void PipelineRun::loop() {
  loop_start_ = Clock::now();
  loop_start_cpu_ = std::clock();
  cpu_clock_ = options_.output.timing_clock == "cpu";
  SequenceItem item;
  while (true) {
    {
      StageTimer timer(&result_.times.read_s);
      if (!reader_->next(item)) break;
    }
    if (!any_item_) {
      result_.t_first_ns = item.kind == SequenceItem::Kind::kEvents ? item.events.t().front() : item.t_ns;
      any_item_ = true;
    }
    t_now_ = std::max(t_now_, item.t_ns);
    switch (item.kind) {
      case SequenceItem::Kind::kImu: onImu(item); break;
      case SequenceItem::Kind::kEvents: onEvents(item); break;
      case SequenceItem::Kind::kFrame: onFrame(item); break;
      case SequenceItem::Kind::kRange: onRange(item); break;
    }
    afterItem(t_now_);
    const bool stopped = !backend_->status().ok() || pipeline_failure_.has_value();
    if (stopped && options_.output.stop_on_divergence) break;
  }
  result_.t_last_ns = t_now_;
  if (frontend_) {
    result_.events = frontend_->numEventsSeen();
    result_.events_kept = frontend_->numEventsKept();
  }
}

void PipelineRun::finish() {
  {
    StageTimer timer(&result_.times.output_s);
    for (const BackendEstimate& e : backend_->takeEstimates()) writer_->addEstimate(e);
  }
  if (timing_started_ && t_now_ > last_timing_t_)
    writer_->addTiming(io::TimingSample{t_now_, elapsed(), static_cast<std::int64_t>(reader_->eventsRead())});
  result_.backend = backend_->stats();
  result_.poses = writer_->numPoses();
  io::EstimateStatus status;
  const BackendStatus& bs = backend_->status();
  if (!bs.ok()) {
    status.code = statusCode(bs.code);
    status.t_ns = bs.t_ns - offset_ns_;
    status.cause = bs.cause;
  } else if (pipeline_failure_) {
    status = *pipeline_failure_;
  } else if (!backend_->initialized()) {
    status.code = io::EstimateStatus::Code::kFailed;
    status.t_ns = t_now_;
    status.cause = init_mode_ == "static" ? "never initialised: no still IMU window of backend.static_window_s"
                                          : "never initialised: no IMU reading at or after the initialisation time";
  }
  status.initialization_t_ns = result_.initialization_t_ns;
  result_.status = status;
  {
    StageTimer timer(&result_.times.output_s);
    result_.times.total_s = std::chrono::duration<double>(Clock::now() - run_start_).count();
    result_.times.cpu_s = static_cast<double>(std::clock() - run_start_cpu_) / CLOCKS_PER_SEC;
    writer_->finish(status, config::toYaml(options_), formatPipelineSummary(result_, options_));
  }
  result_.times.total_s = std::chrono::duration<double>(Clock::now() - run_start_).count();
  result_.times.cpu_s = static_cast<double>(std::clock() - run_start_cpu_) / CLOCKS_PER_SEC;
}

}  // namespace

PipelineResult runPipeline(const std::string& sequence, const PipelineOptions& options, const std::string& output,
                           const PipelineProgressCallback& progress) {
  PipelineRun run(sequence, options, output, progress);
  return run.run();
}

}  // namespace evio::estimator

#include "render_loop.h"

#include <tbb/task_group.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <limits>
#include <optional>

#include "evio/core/error.h"
#include "evio/core/stopwatch.h"
#include "evio/simulator/adaptive_sampler.h"
#include "evio/simulator/event_camera.h"
#include "evio/simulator/frame_camera.h"
#include "evio/simulator/renderer.h"
#include "evio/simulator/tile_schedule.h"
#include "parallel_for.h"

namespace evio::simulator {

namespace {

constexpr TimeNs kNever = std::numeric_limits<TimeNs>::max();

/// Velocity of a camera C rigidly mounted at T_B_C, in C, from the body's state:
///   ṗ_W_C = v_W + R_W_B (ω_B × p_B_C),  v_C = R_W_Cᵀ ṗ_W_C,  ω_C = R_B_Cᵀ ω_B.
CameraVelocity cameraVelocity(const TrajectoryState& s, const Pose& T_B_C) {
  const Mat3 R_W_B = s.T_W_B.rotation();
  const Mat3 R_B_C = T_B_C.rotation();
  const Vec3 p_dot_W = s.v_W + R_W_B * s.omega_B.cross(T_B_C.translation());
  CameraVelocity v;
  v.v_C = (R_W_B * R_B_C).transpose() * p_dot_W;
  v.omega_C = R_B_C.transpose() * s.omega_B;
  return v;
}

AdaptiveSampler::Options samplerOptions(const RenderScheduleOptions& o) {
  AdaptiveSampler::Options s;
  s.lambda = o.lambda;
  s.min_rate_hz = o.min_rate_hz;
  s.max_rate_hz = o.max_rate_hz;
  s.rate_bound = o.rate_bound;
  return s;
}

/// The next render interval: λ C over the q-quantile of the predicted
/// per-pixel |dL/dt|, within the sampler's rate bounds. Rows in parallel
/// (each writes its own entries, so the result does not depend on the
/// thread count).
class StepPredictor {
 public:
  StepPredictor(const RenderScheduleOptions& o, const EventCamera::Options& ec, int threads)
      : sampler_(samplerOptions(o), std::min(ec.threshold_pos, ec.threshold_neg), ec.logEpsilon()),
        quantile_(o.fastest_pixel_quantile),
        threads_(threads) {}

  TimeNs interval(const cv::Mat& radiance, const cv::Mat& flow) {
    const int w = radiance.cols, h = radiance.rows;
    if (w == 0 || h == 0) return sampler_.interval(0.0f);
    log_.create(h, w, CV_32FC1);
    rates_.resize(static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
    constexpr std::size_t kRowsPerTask = 8;
    parallelFor(threads_, static_cast<std::size_t>(h), kRowsPerTask,
                [&](std::size_t y) { sampler_.logRow(radiance, static_cast<int>(y), 0, w, &log_); });
    parallelFor(threads_, static_cast<std::size_t>(h), kRowsPerTask, [&](std::size_t y) {
      sampler_.logRatesOfRow(log_, flow, static_cast<int>(y), 0, w, rates_.data() + y * static_cast<std::size_t>(w));
    });
    float rate = 0.0f;
    if (quantile_ >= 1.0) {
      rate = *std::max_element(rates_.begin(), rates_.end());
    } else {
      const auto k = static_cast<std::ptrdiff_t>(quantile_ * static_cast<double>(rates_.size() - 1));
      rate = AdaptiveSampler::kthSmallest(&rates_, static_cast<std::size_t>(k));
    }
    return sampler_.interval(rate);
  }

 private:
  AdaptiveSampler sampler_;
  double quantile_;
  int threads_;
  cv::Mat log_;               ///< L = log(ε + I) of the latest render
  std::vector<float> rates_;  ///< predicted |dL/dt| per pixel (1/s), row-major
};

/// t = target^γ · full_well / (K · mean radiance) within the exposure limits:
/// the exposure that fills the mean pixel's well to the fraction target^γ
/// (legacy sensor: mean DN / 255 = target), NaN and negative radiance
/// counting as 0. Called with auto-exposure on only.
double meteredExposure(const cv::Mat& radiance, const FrameCamera::Options& o, const FrameCamera& camera) {
  double sum = 0.0;
  for (int y = 0; y < radiance.rows; ++y) {
    const float* r = radiance.ptr<float>(y);
    for (int x = 0; x < radiance.cols; ++x) sum += r[x] > 0.0f ? static_cast<double>(r[x]) : 0.0;
  }
  const double mean = sum / (static_cast<double>(radiance.rows) * static_cast<double>(radiance.cols));
  const double lo = o.auto_exposure_min_s;
  const double hi = o.auto_exposure_max_s;
  if (!(mean > 0.0)) return hi;
  const double t = std::pow(o.auto_exposure_target, o.gamma) * o.full_well_e /
                   (camera.electronsPerRadianceSecond() * mean);
  return std::clamp(t, lo, hi);
}

/// The exposure of one frame: its sub-sample times and the images so far.
struct FrameInProgress {
  std::size_t index = 0;
  TimeNs start_ns = 0;
  TimeNs stamp_ns = 0;             ///< middle of the span, as FrameCamera::capture stamps it
  std::vector<TimeNs> sample_ns;   ///< N times, both ends of the span included
  std::vector<cv::Mat> images;
  bool depth_done = false;
  TimeNs next() const { return sample_ns[images.size()]; }
};

/// f() on the calling thread in the simulator's arena, isolated: while it
/// waits for its own parallel loops the thread runs none of the arena's
/// other tasks (an event stage that another thread would start, below), so
/// the render or schedule it runs is not held up by one.
template <class F>
void isolated(int threads, const F& f) {
  if (threads == 1) {
    f();
    return;
  }
  sharedArena(threads).execute([&] { tbb::this_task_arena::isolate([&] { f(); }); });
}

/// The event stage of a step: the event camera fed with the step's pixels
/// (update for a whole render, updateRects for the tiles due) and its events
/// handed to the writer. With more than one thread it runs as a task in the
/// simulator's TBB arena while the calling thread goes on with the next
/// step's schedule and render (nothing of which reads the event camera);
/// the next launch waits for it. The events and the camera's state are
/// those of the serial order: one stage at a time, in step order.
class EventStage {
 public:
  EventStage(EventCamera* camera, AsyncSequenceWriter* writer, int threads)
      : camera_(*camera), writer_(*writer), threads_(threads) {}
  ~EventStage() {
    try {
      wait();
    } catch (...) {  // unwinding already, or the error was reported
    }
  }
  EventStage(const EventStage&) = delete;
  EventStage& operator=(const EventStage&) = delete;

  /// Every pixel sampled at t. With copy, `radiance` is copied first;
  /// without, it must not change until the stage has ended (the next
  /// launch or wait()).
  void launchWhole(TimeNs t, const cv::Mat& radiance, bool copy) {
    wait();
    whole_ = true;
    t_ = t;
    if (copy) {
      radiance.copyTo(own_);
      radiance_ = own_;
    } else {
      radiance_ = radiance;
    }
    launch();
  }
  /// The pixels of `rects` sampled at t; they are copied out of `radiance`
  /// first (only they), so it may change as soon as this returns.
  void launchRects(TimeNs t, const std::vector<cv::Rect>& rects, const cv::Mat& radiance) {
    wait();
    whole_ = false;
    t_ = t;
    rects_ = rects;
    require(radiance.type() == CV_32FC1, "EventStage: radiance must be CV_32FC1");
    own_.create(radiance.size(), radiance.type());
    const cv::Rect image(0, 0, radiance.cols, radiance.rows);
    for (const cv::Rect& r : rects_)
      for (int y = r.y; y < r.y + r.height && (r & image) == r; ++y)  // (updateRects rejects the others)
        std::memcpy(own_.ptr<float>(y) + r.x, radiance.ptr<float>(y) + r.x, static_cast<std::size_t>(r.width) * sizeof(float));
    radiance_ = own_;
    launch();
  }
  /// Waits for the running stage; rethrows its error.
  void wait() {
    if (running_) {
      sharedArena(threads_).execute([this] { group_.wait(); });
      running_ = false;
    }
    radiance_.release();
    if (error_) {
      const std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }

  double event_s = 0.0, event_cpu_s = 0.0, write_s = 0.0;  ///< wall time, CPU time of the running thread, queueing

 private:
  void launch() {
    if (threads_ == 1) {
      run();
      wait();  // releases the image; rethrows an error
      return;
    }
    running_ = true;
    sharedArena(threads_).execute([this] { group_.run([this] { run(); }); });
  }
  void run() {
    try {
      Stopwatch watch;
      const double cpu0_s = Stopwatch::threadCpuSeconds();
      batch_.clear();
      labels_.clear();
      if (whole_) {
        camera_.update(t_, radiance_, &batch_, &labels_);
      } else {
        camera_.updateRects(t_, rects_, radiance_);
        camera_.emit(&batch_, &labels_);
      }
      event_s += watch.seconds();
      event_cpu_s += Stopwatch::threadCpuSeconds() - cpu0_s;
      watch.restart();
      writer_.appendEvents(batch_, labels_);
      write_s += watch.seconds();
    } catch (...) {
      error_ = std::current_exception();
    }
  }

  EventCamera& camera_;
  AsyncSequenceWriter& writer_;
  int threads_;
  tbb::task_group group_;
  bool running_ = false;
  std::exception_ptr error_;
  bool whole_ = true;
  TimeNs t_ = 0;
  std::vector<cv::Rect> rects_;
  cv::Mat radiance_;  ///< the stage's input image while it runs
  cv::Mat own_;       ///< the copied pixels (tile schedule)
  EventArray batch_;
  std::vector<EventLabel> labels_;
};

}  // namespace

RenderLoopResult runRenderLoop(const Scenario& scenario, const scenes::Scene& scene, AsyncSequenceWriter& writer,
                               const ProgressCallback& progress, SimulationStats* stats) {
  const ScenarioOptions& o = scenario.options;
  const auto& fo = o.rig.frame_camera;
  const ContinuousTrajectory& trajectory = *scenario.trajectory;
  const Camera event_cam = scenario.eventCamera();
  const Pose T_B_E = scenario.T_B_E();

  RendererOptions ro;
  ro.threads = o.threads;
  ro.supersampling = o.sampling.supersampling;
  ro.tile_px = o.sampling.tilePx();
  const Renderer renderer(scene, event_cam, ro);
  std::optional<Renderer> frame_renderer;
  const bool frames = fo.enabled;
  const bool separate = frames && !fo.co_located;
  const Pose T_B_F = frames ? scenario.T_B_F() : Pose();
  if (separate) frame_renderer.emplace(scene, scenario.frameCamera(), ro);

  EventCamera::Options eo = o.rig.event_camera.sensor.event_camera;
  eo.threads = o.threads;
  EventCamera events_cam(event_cam.width(), event_cam.height(), eo, o.seed);
  StepPredictor predictor(o.sampling, eo, o.threads);
  const bool tile_mode = o.sampling.tiles();
  std::optional<TileSchedule> tile_schedule;
  if (tile_mode)
    tile_schedule.emplace(event_cam.width(), event_cam.height(), o.sampling.tilePx(), samplerOptions(o.sampling),
                          std::min(eo.threshold_pos, eo.threshold_neg), eo.logEpsilon(), scenario.start_ns,
                          o.sampling.tileQuantumNs(), o.threads);
  stats->schedule = o.sampling.schedule;
  stats->tile_count = static_cast<std::uint64_t>(renderer.tileCount());
  std::optional<FrameCamera> frame_cam;
  if (frames) {
    FrameCamera::Options fco = fo.sensor;
    fco.threads = o.threads;
    // The exposure never outlasts the frame period minus the readout.
    fco.auto_exposure_max_s = std::min(fco.auto_exposure_max_s, 1.0 / fo.rate_hz - fco.readout_s);
    fco.auto_exposure_min_s = std::min(fco.auto_exposure_min_s, fco.auto_exposure_max_s);
    const Camera c = scenario.frameCamera();
    if (fo.meter_first_exposure && fco.auto_exposure) {
      const Pose T_W_F = trajectory.evaluate(scenario.start_ns).T_W_B * T_B_F;
      const Stopwatch watch;
      const RenderOutput view = (separate ? *frame_renderer : renderer).render(T_W_F);
      stats->frame_render_s += watch.seconds();
      ++stats->frame_renders;
      fco.exposure_s = meteredExposure(view.radiance, fco, FrameCamera(c.width(), c.height(), fco, o.seed));
    }
    frame_cam.emplace(c.width(), c.height(), fco, o.seed);
  }
  const bool depth_on = frames && o.output.depth_at_frames;

  // Frame k's exposure starts at start + round(k / rate_hz); the frame is
  // taken only when its whole exposure lies inside the window.
  std::size_t frame_k = 0;
  bool frames_done = !frames;
  std::optional<FrameInProgress> frame;
  const auto beginFrame = [&] {
    const TimeNs start = scenario.start_ns + static_cast<TimeNs>(std::llround(static_cast<double>(frame_k) * 1e9 / fo.rate_hz));
    // The frame's span: the first row's exposure start to the last row's end.
    const double span = frame_cam->frameSpanS(frame_cam->exposureS());
    if (start + secondsToNs(span) > scenario.end_ns) {
      frames_done = true;
      return;
    }
    FrameInProgress f;
    f.index = frame_k;
    f.start_ns = start;
    f.stamp_ns = start + secondsToNs(0.5 * span);
    const int n = fo.exposure_samples;
    for (int j = 0; j < n; ++j) {
      // The middle sample of an odd N is exactly the stamp (one render serves both).
      const TimeNs t = n == 1 ? start
                       : 2 * j == n - 1 ? f.stamp_ns
                                        : start + secondsToNs(span * static_cast<double>(j) / (n - 1));
      if (f.sample_ns.empty() || t > f.sample_ns.back()) f.sample_ns.push_back(t);
    }
    frame = std::move(f);
  };
  const auto addSample = [&](const cv::Mat& radiance) {
    frame->images.push_back(radiance);
    if (frame->images.size() < frame->sample_ns.size()) return;
    Stopwatch watch;
    Frame captured;
    isolated(o.threads, [&] { captured = frame_cam->capture(frame->start_ns, frame->images); });
    stats->frame_s += watch.seconds();
    watch.restart();
    writer.appendFrame(captured.t_ns, captured.image);
    stats->write_s += watch.seconds();
    frame.reset();
    ++frame_k;
  };

  RenderLoopResult result;
  TimeNs next_event = scenario.start_ns;  // the next whole-frame step ("whole_frame")
  TimeNs last_t = kNever;
  // The latest sample of every pixel: *last. The whole-frame schedule
  // renders into the two buffers in turn, so that the event stage of one
  // render reads its image while the next render fills the other; the tile
  // schedule keeps one (a step re-traces only some tiles of it).
  RenderOutput buffers[2];
  RenderOutput* last = &buffers[0];
  std::vector<int> due_tiles;
  std::vector<cv::Rect> due_rects;
  EventStage event_stage(&events_cam, &writer, o.threads);
  // Every pixel sampled at t: a whole render, EventCamera::update (which
  // emits every event up to t), and the next step predicted from it.
  const auto wholeStep = [&](TimeNs t, const Pose& T_W_E, const CameraVelocity& velocity) {
    if (!tile_mode) last = last == &buffers[0] ? &buffers[1] : &buffers[0];
    Stopwatch watch;
    const double cpu0_s = Stopwatch::processCpuSeconds();
    isolated(o.threads, [&] { renderer.render(T_W_E, &velocity, last); });  // reuses last's images unless shared
    stats->render_s += watch.seconds();
    stats->render_cpu_s += Stopwatch::processCpuSeconds() - cpu0_s;
    ++stats->renders;
    stats->tiles_rendered += stats->tile_count;

    event_stage.launchWhole(t, last->radiance, tile_mode);  // after the previous step's stage

    watch.restart();
    isolated(o.threads, [&] {
      if (tile_mode) {
        tile_schedule->scheduleAll(t, last->radiance, last->flow);
      } else if (t < scenario.end_ns) {  // the next step, predicted from this (latest) sample
        next_event = t + predictor.interval(last->radiance, last->flow);
      }
    });
    stats->schedule_s += watch.seconds();
  };
  // The tiles due at t only: renderTiles, their pixels to the event camera,
  // the events up to the watermark (the earliest last sample of any pixel).
  const auto tileStep = [&](TimeNs t, const Pose& T_W_E, const CameraVelocity& velocity) {
    Stopwatch watch;
    const double cpu0_s = Stopwatch::processCpuSeconds();
    tile_schedule->dueTiles(t, &due_tiles);
    isolated(o.threads, [&] { renderer.renderTiles(T_W_E, &velocity, due_tiles.data(), due_tiles.size(), last); });
    stats->render_s += watch.seconds();
    stats->render_cpu_s += Stopwatch::processCpuSeconds() - cpu0_s;
    ++stats->tile_steps;
    stats->tiles_rendered += due_tiles.size();

    due_rects.clear();
    for (const int k : due_tiles) due_rects.push_back(renderer.tileRect(k));
    event_stage.launchRects(t, due_rects, last->radiance);

    watch.restart();
    isolated(o.threads, [&] { tile_schedule->scheduleTiles(t, due_tiles, last->radiance, last->flow); });
    stats->schedule_s += watch.seconds();
  };

  const double total_s = nsToSeconds(scenario.end_ns - scenario.start_ns);
  while (true) {
    if (!frames_done && !frame) beginFrame();
    const TimeNs t_frame = frame ? frame->next() : kNever;
    const TimeNs t_depth = frame && depth_on && !frame->depth_done ? frame->stamp_ns : kNever;
    const TimeNs t_step = tile_mode && last_t != kNever ? tile_schedule->nextTime() : next_event;
    const TimeNs t = std::min({t_step, scenario.end_ns, t_depth, separate ? kNever : t_frame});

    if (separate && t_frame <= t) {  // a separate frame camera's own sub-sample
      const Pose T_W_F = trajectory.evaluate(t_frame).T_W_B * T_B_F;
      const Stopwatch watch;
      RenderOutput out = frame_renderer->render(T_W_F);
      stats->frame_render_s += watch.seconds();
      ++stats->frame_renders;
      addSample(out.radiance);
      continue;
    }

    if (t != last_t) {
      const TrajectoryState state = trajectory.evaluate(t);
      const Pose T_W_E = state.T_W_B * T_B_E;
      const CameraVelocity velocity = cameraVelocity(state, T_B_E);
      // Frames, depth truth and the end need every pixel at t, exactly.
      const bool whole = !tile_mode || last_t == kNever || t == scenario.end_ns || t == t_depth ||
                         (!separate && t == t_frame);
      if (whole) {
        wholeStep(t, T_W_E, velocity);
      } else {
        tileStep(t, T_W_E, velocity);
      }
      if (last_t == kNever) {
        result.first_depth = last->depth.clone();
        result.first_T_W_E = T_W_E;
      }
      last_t = t;
    }
    if (!separate && frame && t == t_frame) addSample(last->radiance);
    if (frame && t == t_depth) {
      const Stopwatch watch;
      writer.appendDepth(frame->index, t, last->depth, o.output.flow_at_frames ? last->flow : cv::Mat());
      stats->write_s += watch.seconds();
      frame->depth_done = true;
    }
    if (progress)
      progress(SimulationProgress{nsToSeconds(t - scenario.start_ns), total_s, writer.eventCount(), stats->renders,
                                  stats->tiles_rendered});
    if (t >= scenario.end_ns) break;
  }
  event_stage.wait();
  stats->event_s += event_stage.event_s;
  stats->event_cpu_s += event_stage.event_cpu_s;
  stats->write_s += event_stage.write_s;
  stats->pixel_updates = events_cam.pixelUpdates();
  return result;
}

}  // namespace evio::simulator

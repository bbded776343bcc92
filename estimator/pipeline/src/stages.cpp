#include "evio/estimator/pipeline/stages.h"

#include <utility>

namespace evio::estimator {

// --- PrefilterStage ------------------------------------------------------------------

PrefilterStage::PrefilterStage(const EventPrefilterOptions& options, int width, int height) {
  if (!options.passThrough()) filter_ = std::make_unique<EventPrefilter>(options, width, height);
}

void PrefilterStage::process(SequenceItem& in, std::vector<SequenceItem>& out) {
  if (in.kind == SequenceItem::Kind::kEvents) {
    seen_ += in.events.size();
    if (filter_) {
      filter_->filter(in.events, 0, in.events.size(), &filtered_);
      std::swap(in.events, filtered_);  // the spare buffer goes back with the item
    }
    kept_ += in.events.size();
  }
  out.emplace_back();
  std::swap(out.back(), in);
}

// --- FrontendStage -------------------------------------------------------------------

FrontendStage::FrontendStage(const FrontendOptions& options, const CameraSensor& camera, double still_probe_s)
    : frontend_(options, camera.camera, camera.T_B_C), still_probe_(still_probe_s) {
  // Segments serve the threads; on one they would only add latency.
  if (options.segment_s > 0.0 && options.threads > 1 && frontend_.tracksEventChunks())
    segment_ns_ = secondsToNs(options.segment_s);
}

const EkltTiming* FrontendStage::ekltTiming() const {
  const auto* eklt = dynamic_cast<const EkltTracker*>(&frontend_.tracker());
  return eklt ? &eklt->timing() : nullptr;
}

void FrontendStage::process(SequenceItem& in, std::vector<FrontendOutput>& out) {
  if (segment_ns_ > 0) {
    const bool holdable = in.kind == SequenceItem::Kind::kEvents ||
                          (in.kind == SequenceItem::Kind::kImu && !held_.empty());
    if (holdable) {
      if (hold(in)) flushSegment(out);
      return;
    }
    flushSegment(out);  // a frame or range reading: the events before it are tracked first
  }
  processNow(in, out);
}

bool FrontendStage::hold(SequenceItem& in) {
  Held& h = held_.emplace_back();
  h.output.kind = in.kind;
  h.output.t_ns = in.t_ns;
  if (in.kind == SequenceItem::Kind::kEvents) {
    segment_events_.append(in.events);
    h.output.events = in.events.size();
    h.events_end = segment_events_.size();
  } else {
    // The trackers that take segments ignore the IMU: its place among the
    // events does not matter to them.
    ImuSample camera_clock = in.imu;
    camera_clock.t_ns = in.t_ns;
    frontend_.addImu(camera_clock);
    h.output.imu = in.imu;
  }
  return in.t_ns - held_.front().output.t_ns >= segment_ns_ || segment_events_.size() >= kMaxSegmentEvents;
}

void FrontendStage::flushSegment(std::vector<FrontendOutput>& out) {
  if (held_.empty()) return;
  chunk_ends_.clear();
  point_ends_.clear();
  segment_points_.clear();
  for (const Held& h : held_)
    if (h.output.kind == SequenceItem::Kind::kEvents) chunk_ends_.push_back(h.events_end);
  frontend_.addEventChunks(segment_events_, chunk_ends_, segment_points_, point_ends_);
  std::size_t chunk = 0, begin = 0;
  for (Held& h : held_) {
    if (h.output.kind == SequenceItem::Kind::kEvents) {
      const std::size_t end = point_ends_[chunk++];
      h.output.points.assign(segment_points_.begin() + static_cast<std::ptrdiff_t>(begin),
                             segment_points_.begin() + static_cast<std::ptrdiff_t>(end));
      begin = end;
    }
    out.push_back(std::move(h.output));
  }
  held_.clear();
  segment_events_.clear();
}

void FrontendStage::processNow(SequenceItem& in, std::vector<FrontendOutput>& out) {
  FrontendOutput& o = out.emplace_back();
  o.kind = in.kind;
  o.t_ns = in.t_ns;
  switch (in.kind) {
    case SequenceItem::Kind::kEvents:
      frontend_.addEvents(in.events);
      o.events = in.events.size();
      frontend_.drainTrackPoints(o.points);
      break;
    case SequenceItem::Kind::kFrame:
      frontend_.addFrame(in.t_ns, in.image);
      o.still_corners = still_probe_.addFrame(in.t_ns, in.image);
      ++frames_;
      frontend_.drainTrackPoints(o.points);
      o.lag = frontend_.trackLag();
      break;
    case SequenceItem::Kind::kImu: {
      ImuSample camera_clock = in.imu;
      camera_clock.t_ns = in.t_ns;
      frontend_.addImu(camera_clock);
      o.imu = in.imu;
      break;
    }
    case SequenceItem::Kind::kRange: o.range = in.range; break;
  }
}

// --- SynchronizerStage ---------------------------------------------------------------

void SynchronizerStage::process(FrontendOutput& in, std::vector<BackendInput>& out) {
  if (!in.points.empty()) {
    track_points_ += in.points.size();
    sync_.addTrackPoints(in.points);
  }
  switch (in.kind) {
    case SequenceItem::Kind::kEvents: sync_.addEvents(in.events, in.t_ns); break;
    case SequenceItem::Kind::kFrame:
      if (in.lag) sync_.setTrackLag(in.lag->a_px, in.lag->tau_s);
      sync_.advanceTime(in.t_ns);
      if (in.still_corners) out.emplace_back(std::move(*in.still_corners));
      break;
    case SequenceItem::Kind::kImu:
      sync_.advanceTime(in.t_ns);
      out.emplace_back(in.imu);
      break;
    case SequenceItem::Kind::kRange:
      if (in.range.valid) out.emplace_back(RangeMeasurement{in.t_ns, in.range.range_m});
      break;
  }
  MeasurementSet set;
  while (sync_.poll(&set)) out.emplace_back(std::move(set));
}

// --- TracksStage ---------------------------------------------------------------------

void TracksStage::process(SequenceItem& in, std::vector<BackendInput>& out) {
  if (in.kind == SequenceItem::Kind::kRange && in.range.valid)
    out.emplace_back(RangeMeasurement{in.t_ns, in.range.range_m});
  if (in.kind != SequenceItem::Kind::kImu) return;
  out.emplace_back(in.imu);
  input_->advanceTo(in.t_ns, sets_);
  for (MeasurementSet& s : sets_) out.emplace_back(std::move(s));
  sets_.clear();
}

// --- BackendStage --------------------------------------------------------------------

BackendStage::BackendStage(Backend& backend, std::optional<GroundTruthInitializer> initializer,
                           std::optional<GyroBiasWindow> gyro_bias_window)
    : backend_(backend), initializer_(std::move(initializer)), window_(std::move(gyro_bias_window)) {
  if (!initializer_) backend_.setAutoStaticInitialization(true);
}

void BackendStage::process(BackendInput& in, std::vector<Estimate>& out) {
  if (window_ && window_->collecting()) {
    if (window_->add(std::move(in))) closeWindow(out);
    return;
  }
  if (const auto* imu = std::get_if<ImuSample>(&in); imu && initializer_ && !backend_.initialized() && !gyro_bias_) {
    if (const std::optional<ImuState> x0 = initializer_->offer(imu->t_ns)) {
      if (window_) {
        window_->open(*x0);
        if (window_->add(std::move(in))) closeWindow(out);
        return;
      }
      backend_.initialize(*x0);
    }
  }
  feed(in, out);
}

void BackendStage::finish(std::vector<Estimate>& out) {
  if (window_ && window_->collecting()) closeWindow(out);
  backend_.finish();
}

void BackendStage::closeWindow(std::vector<Estimate>& out) {
  const Eigen::Matrix<double, 15, 15> P0 = backend_.initialCovariance();
  gyro_bias_ = window_->estimate(P0);
  if (const auto& rest = window_->restStart()) {
    // At rest the window is the initialisation: the filter starts at its end
    // with the rest update's state and covariance, and takes the inputs from
    // then on (propagating through the readings the update averaged, it
    // would take their noise twice).
    startFilter(rest->first, rest->second);
    for (BackendInput& in : window_->takeInputsFrom(rest->first.t_ns)) feed(in, out);
    return;
  }
  ImuState x0 = window_->initialState();
  x0.b_g = gyro_bias_->b_g;
  // P0 with the bias block replaced by the tracks' covariance (no
  // correlation with the rest of the state, which the window did not see).
  const auto with_window_sigma = [&] {
    Eigen::Matrix<double, 15, 15> P = P0;
    P.block<3, 15>(kIdxBg, 0).setZero();
    P.block<15, 3>(0, kIdxBg).setZero();
    P.block<3, 3>(kIdxBg, kIdxBg) = gyro_bias_->covariance;
    return P;
  };
  if (window_->tracksOnce() && gyro_bias_->from_tracks) {
    // The window's tracks are used once, by the window: the filter starts
    // with the estimate and its covariance, and takes only the window's IMU
    // and range readings.
    startFilter(x0, with_window_sigma());
    for (BackendInput& in : window_->takeInputs())
      if (!std::holds_alternative<MeasurementSet>(in)) feed(in, out);
    return;
  }
  // The tracks' estimate moves the bias's mean, the point the filter
  // linearises at. Its covariance stays the prior's unless asked otherwise
  // (init.gyro_bias_window_sigma): the filter is about to take the window's
  // tracks again, and told both it counts them twice where it updates
  // inside the window.
  const bool window_sigma = window_->replayWithWindowSigma() && gyro_bias_->from_tracks;
  startFilter(x0, window_sigma ? with_window_sigma() : P0);
  for (BackendInput& in : window_->takeInputs()) feed(in, out);
}

void BackendStage::startFilter(const ImuState& x0, const Eigen::Matrix<double, 15, 15>& P) {
  gyro_bias_->filter_start_covariance = P.block<3, 3>(kIdxBg, kIdxBg);
  backend_.initialize(x0, P);
}

void BackendStage::feed(BackendInput& in, std::vector<Estimate>& out) {
  if (const auto* imu = std::get_if<ImuSample>(&in)) {
    backend_.addImu(*imu);
  } else if (const auto* set = std::get_if<MeasurementSet>(&in)) {
    backend_.addMeasurementSet(*set);
    ++measurement_sets_;
    last_set_features_ = set->features.size();
  } else if (const auto* range = std::get_if<RangeMeasurement>(&in)) {
    backend_.addRange(range->t_ns, range->range_m);
  }  // FrameCorners: the first window's evidence only (gyro_bias_window.h)
  for (Estimate& e : backend_.takeEstimates()) out.push_back(std::move(e));
}

}  // namespace evio::estimator

#include "evio/estimator/frontend/frontend.h"

#include <string>

#include "evio/core/error.h"
#include "evio/core/options.h"
#include "evio/estimator/frontend/eklt_tracker.h"
#include "evio/estimator/frontend/haste_tracker.h"

namespace evio::estimator {

void FrontendOptions::validate() const {
  requireField(tracker == "eklt" || tracker == "klt" || tracker == "haste", "tracker",
               "must be eklt, klt or haste (got '" + tracker + "')");
  requireField(image_source == "frames" || image_source == "reconstructed", "image_source",
               "must be frames or reconstructed (got '" + image_source + "')");
  requireField(threads >= 1 && threads <= 64, "threads", "must be in [1, 64]");
  requireField(segment_s >= 0.0 && segment_s <= 1.0, "segment_s", "must be in [0, 1] s");
  validateSection("prefilter", prefilter);
  validateSection("eklt", eklt);
  validateSection("klt", klt);
  validateSection("haste", haste);
  validateSection("reconstruction", reconstruction);
  validateSection("track_lag", track_lag);
}

FrontendOptions resolveSensorParameters(FrontendOptions options,
                                        const std::map<std::string, double>& event_camera_parameters) {
  const auto on = event_camera_parameters.find("contrast_threshold_pos");
  const auto off = event_camera_parameters.find("contrast_threshold_neg");
  const bool stated = on != event_camera_parameters.end() && off != event_camera_parameters.end() &&
                      on->second > 0.0 && off->second > 0.0;
  const double c_on = stated ? on->second : kDavis240cThresholdOn;
  const double c_off = stated ? off->second : kDavis240cThresholdOff;
  if (options.eklt.batch_contrast_threshold == 0.0) options.eklt.batch_contrast_threshold = 0.5 * (c_on + c_off);
  ImageReconstructorOptions& r = options.reconstruction;
  if (r.contrast_threshold == 0.0) {
    r.contrast_threshold = c_on;
    if (r.contrast_threshold_neg == 0.0) r.contrast_threshold_neg = c_off;
  }
  return options;
}

Frontend::Frontend(const FrontendOptions& options, const Camera& camera, std::optional<Pose> T_B_C)
    : options_(options) {
  options_.validate();
  // The tracker, and what its section states with every point (EKLT states
  // each point's covariance itself).
  if (options_.tracker == "eklt") {
    tracker_ = std::make_unique<EkltTracker>(options_.eklt, camera, T_B_C, options_.threads);
    error_time_s_ = options_.eklt.error_time_s;
  } else if (options_.tracker == "haste") {
    tracker_ = std::make_unique<HasteTracker>(options_.haste, camera, options_.threads);
    error_time_s_ = options_.haste.error_time_s;
    position_sigma_px_ = options_.haste.position_sigma_px;
  } else {
    tracker_ = std::make_unique<KltTracker>(options_.klt, camera, T_B_C);
    error_time_s_ = options_.klt.error_time_s;
    position_sigma_px_ = options_.klt.position_sigma_px;
  }
  if (options_.image_source == "reconstructed")
    reconstructor_ = std::make_unique<ImageReconstructor>(options_.reconstruction, camera.width(), camera.height());
  if (options_.track_lag.estimate && options_.tracker != "klt")
    probe_ = std::make_unique<FrameLagProbe>(options_.track_lag);
}

Frontend::~Frontend() = default;

void Frontend::addEvents(const EventArray& events) {
  events_ += events.size();
  if (!reconstructor_) {
    tracker_->addEvents(events, 0, events.size());
    return;
  }
  std::size_t begin = 0;
  while (begin < events.size()) {
    const std::size_t end = reconstructor_->addEvents(events, begin, events.size());
    tracker_->addEvents(events, begin, end);
    if (reconstructor_->frameDue()) {
      const TimeNs t = reconstructor_->dueTime();
      tracker_->addFrame(t, reconstructor_->image(t));
      ++reconstructed_frames_;
    }
    begin = end;
  }
}

bool Frontend::tracksEventChunks() const { return !reconstructor_ && !usesImu(); }

bool Frontend::usesImu() const { return tracker_->usesImu(); }

void Frontend::addEventChunks(const EventArray& events, const std::vector<std::size_t>& chunk_ends, TrackPoints& out,
                              std::vector<std::size_t>& point_ends) {
  require(tracksEventChunks(), "Frontend::addEventChunks: the tracker takes more than events between chunks");
  events_ += chunk_ends.empty() ? 0 : chunk_ends.back();
  const std::size_t begin = out.size();
  tracker_->addEventChunks(events, chunk_ends, out, point_ends);
  stateNoise(out, begin);
  if (probe_) probe_->observe(out, begin);
}

void Frontend::drainTrackPoints(TrackPoints& out) {
  const std::size_t begin = out.size();
  tracker_->drainTrackPoints(out);
  stateNoise(out, begin);
  unmarkReconstructedFramePoints(out, begin);
  if (probe_) probe_->observe(out, begin);
}

void Frontend::stateNoise(TrackPoints& points, std::size_t begin) const {
  const Mat2 stated = position_sigma_px_ * position_sigma_px_ * Mat2::Identity();
  for (std::size_t i = begin; i < points.size(); ++i) {
    points[i].error_time_s = error_time_s_;
    if (position_sigma_px_ > 0.0 && points[i].cov_px == Mat2::Zero()) points[i].cov_px = stated;
  }
}

void Frontend::unmarkReconstructedFramePoints(TrackPoints& points, std::size_t begin) const {
  if (!reconstructor_) return;
  for (std::size_t i = begin; i < points.size(); ++i) points[i].measured_on_frame = false;
}

void Frontend::addFrame(TimeNs t_ns, const cv::Mat& image) {
  // The probe first: it compares the event tracks up to this frame with the
  // frame, then sees the tracker's new seeds on it (drainTrackPoints).
  if (probe_) probe_->addFrame(t_ns, image);
  if (reconstructor_)
    reconstructor_->addFrame(t_ns, image);
  else
    tracker_->addFrame(t_ns, image);
}

void Frontend::addImu(const ImuSample& sample) { tracker_->addImu(sample); }

}  // namespace evio::estimator

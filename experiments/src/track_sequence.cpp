#include "evio/experiments/track_sequence.h"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <unordered_map>

#include "evio/core/error.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/stopwatch.h"
#include "evio/estimator/frontend/event_prefilter.h"
#include "evio/estimator/frontend/track_velocity.h"
#include "evio/experiments/sequence_info.h"

namespace evio::experiments {

namespace {

namespace fs = std::filesystem;

/// Events in time order from events.h5 or events.txt, handed out up to a time.
class EventSource {
 public:
  /// `required`: a folder without events is an error (else it gives no events).
  EventSource(const std::string& folder, bool required) {
    const fs::path h5 = fs::path(folder) / "events.h5";
    const fs::path txt = fs::path(folder) / "events.txt";
    if (fs::exists(h5)) {
      h5_ = std::make_unique<io::EventH5Reader>(h5.string());
      total_ = h5_->size();
    } else if (fs::exists(txt)) {
      txt_ = std::make_unique<io::EventTextReader>(txt.string());
      total_ = static_cast<std::uint64_t>(fs::file_size(txt) / 24);  // ~bytes per line, for progress only
    } else if (required) {
      throw Error(folder + ": no events.h5 or events.txt");
    }
  }

  /// Replaces `out` with the next events with t < t_end_ns (all when
  /// t_end_ns is nullopt), at most about `max` at a time; false when none.
  bool next(EventArray& out, std::optional<TimeNs> t_end_ns, std::size_t max = 1u << 16) {
    out.clear();
    if (pos_ >= buffer_.size()) {
      buffer_.clear();
      pos_ = 0;
      if (!h5_ && !txt_) return false;  // a frames-only folder (KLT)
      const bool more = h5_ ? h5_->next(buffer_, max) : txt_->next(buffer_, max);
      if (!more) return false;
      read_ += buffer_.size();
    }
    std::size_t end = buffer_.size();
    if (t_end_ns) end = std::max(pos_, std::min(end, buffer_.lowerBound(*t_end_ns)));
    if (end == pos_) return false;
    out.reserve(end - pos_);
    for (std::size_t i = pos_; i < end; ++i) out.push_back(buffer_.t()[i], buffer_.x()[i], buffer_.y()[i], buffer_.p()[i] != 0);
    pos_ = end;
    return true;
  }

  std::uint64_t read() const { return read_; }
  double fraction() const { return total_ > 0 ? std::min(1.0, static_cast<double>(read_) / static_cast<double>(total_)) : 0.0; }

 private:
  std::unique_ptr<io::EventH5Reader> h5_;
  std::unique_ptr<io::EventTextReader> txt_;
  EventArray buffer_;
  std::size_t pos_ = 0;
  std::uint64_t read_ = 0;
  std::uint64_t total_ = 0;
};

struct CameraChoice {
  Camera camera;
  std::optional<Pose> T_B_C;
  std::string name;
  std::map<std::string, double> event_parameters;  ///< the event camera's stated parameters (sensors.yaml)
  TimeNs time_offset_cam_imu_ns = 0;                ///< t_imu = t_cam + offset (sensors.yaml)
};

CameraChoice chooseCamera(const std::string& folder, bool frame_camera,
                          const std::vector<io::ImageStamp>& images) {
  const fs::path sensors = fs::path(folder) / "sensors.yaml";
  if (fs::exists(sensors)) {
    const SensorRig rig = io::readSensorsYaml(sensors.string());
    const CameraSensor* pick = nullptr;
    for (const auto& c : rig.cameras)
      if (c.role == (frame_camera ? CameraRole::kFrame : CameraRole::kEvent)) {
        pick = &c;
        break;
      }
    if (pick == nullptr) pick = &rig.cameras.front();
    const CameraSensor* event = rig.firstCamera(CameraRole::kEvent);
    return CameraChoice{pick->camera, pick->T_B_C, pick->name,
                        event != nullptr ? event->parameters : std::map<std::string, double>{},
                        rig.time_offset_cam_imu_ns};
  }
  const fs::path calib = fs::path(folder) / "calib.txt";
  if (!fs::exists(calib)) throw Error(folder + ": neither sensors.yaml nor calib.txt");
  // calib.txt has no sensor size: the first frame's, else the events' (as `evio info`).
  int width = 0, height = 0;
  std::string size_from;
  if (!images.empty()) {
    const cv::Mat first = io::readFrame(folder, images.front());
    width = first.cols;
    height = first.rows;
  } else {
    const SequenceInfo info = inspectSequence(folder);
    if (info.width <= 0)
      throw Error(folder + ": calib.txt gives no resolution, and there are neither frames nor events to take it from");
    width = info.width;
    height = info.height;
    size_from = " (size from " + info.resolution_source + ")";
  }
  return CameraChoice{io::cameraFromCalibTxt(io::readCalibTxt(calib.string()), width, height), std::nullopt,
                      "calib.txt" + size_from, {}};  // calib.txt states no thresholds
}

/// The frontend for the folder's camera; its errors name the folder (e.g. a
/// gyro prediction without T_B_C, which only sensors.yaml gives).
estimator::Frontend frontendFor(const std::string& folder, const estimator::FrontendOptions& options,
                                const CameraChoice& cam) {
  try {
    return estimator::Frontend(options, cam.camera, cam.T_B_C);
  } catch (const Error& e) {
    throw Error(folder + ": " + e.what());
  }
}

}  // namespace

Vec2 lagCompensated(const estimator::TrackLag& lag, const Vec2& uv, const Vec2& velocity) {
  return estimator::moveAlongVelocity(uv, velocity, lag.tau_s, lag.a_px);
}

TrackSequenceResult trackSequence(const std::string& folder, const estimator::FrontendOptions& requested,
                                  const TrackProgress& progress, std::optional<LagCompensation> compensate_lag) {
  requested.validate();
  if (!fs::is_directory(folder)) throw Error(folder + ": not a folder");
  const bool has_images = fs::exists(fs::path(folder) / "images.txt");
  const std::vector<io::ImageStamp> images = has_images ? io::readImageList(folder) : std::vector<io::ImageStamp>{};
  if (images.empty() && requested.image_source == "frames")
    throw Error(folder + ": no frames (images.txt); use image_source reconstructed");
  const CameraChoice cam = chooseCamera(folder, requested.tracker == "klt", images);
  const estimator::FrontendOptions options = estimator::resolveSensorParameters(requested, cam.event_parameters);
  estimator::Frontend frontend = frontendFor(folder, options, cam);
  ImuSamples imu;
  if (frontend.usesImu()) {  // a gyro prediction
    imu = io::readImuText((fs::path(folder) / "imu.txt").string());
    // On the camera clock, as the pipeline feeds the frontend: t_cam = t_imu − offset.
    for (ImuSample& sample : imu) sample.t_ns -= cam.time_offset_cam_imu_ns;
  }
  // The pre-filters run before the tracker, as in the pipeline's PrefilterStage.
  std::unique_ptr<estimator::EventPrefilter> prefilter;
  if (!options.prefilter.passThrough())
    prefilter = std::make_unique<estimator::EventPrefilter>(options.prefilter, cam.camera.width(), cam.camera.height());
  EventArray filtered;
  std::uint64_t events_seen = 0;
  // KLT tracks on frames alone: a frames-only folder has no events to read.
  EventSource events(folder, /*required=*/options.tracker != "klt");
  TrackSequenceResult result;
  result.camera_name = cam.name;
  result.options = options;
  std::unordered_map<std::int64_t, TimeNs> last_t;
  std::unordered_map<std::int64_t, estimator::TrackVelocity> velocities;  // per track (compensate_lag)
  estimator::TrackPoints points;
  std::size_t next_imu = 0;
  double busy = 0.0;
  // A point measured on a frame (EKLT's detection and bootstrap) does not lag,
  // as the synchroniser takes it.
  const auto compensate = [&](const estimator::TrackPoint& p) {
    io::TrackSample out{p.feature_id, p.t_ns, p.uv};
    auto [it, inserted] = velocities.try_emplace(p.feature_id, compensate_lag->velocity_window_s);
    it->second.add(p.t_ns, p.uv);
    const auto lag = frontend.trackLag();  // the estimate as the points leave the frontend
    const auto v = it->second.velocity();
    if (lag && v && !p.measured_on_frame) out.uv = lagCompensated(*lag, p.uv, *v);
    result.compensated.push_back(out);
  };
  const auto collect = [&] {
    points.clear();
    frontend.drainTrackPoints(points);
    for (const auto& p : points) {
      if (p.status == estimator::TrackStatus::kLost) {
        velocities.erase(p.feature_id);  // as the synchroniser forgets a lost track
        continue;
      }
      auto [it, inserted] = last_t.try_emplace(p.feature_id, p.t_ns);
      if (!inserted) {
        if (p.t_ns <= it->second) continue;  // a track's times must increase in tracks.txt
        it->second = p.t_ns;
      }
      result.samples.push_back(io::TrackSample{p.feature_id, p.t_ns, p.uv});
      result.noise.push_back(io::TrackNoiseSample{p.feature_id, p.t_ns, p.quality, p.cov_px});
      if (compensate_lag) compensate(p);
    }
  };
  const auto feedImuUntil = [&](TimeNs t) {
    while (next_imu < imu.size() && imu[next_imu].t_ns <= t) frontend.addImu(imu[next_imu++]);
  };
  const auto run = [&](auto&& fn) {
    const Stopwatch watch;
    fn();
    busy += watch.seconds();
  };
  EventArray chunk;
  const auto feedEventsUntil = [&](std::optional<TimeNs> t_end) {
    while (events.next(chunk, t_end)) {
      feedImuUntil(chunk.t().back());
      events_seen += chunk.size();
      run([&] {
        if (!prefilter) return frontend.addEvents(chunk);
        prefilter->filter(chunk, 0, chunk.size(), &filtered);
        frontend.addEvents(filtered);
      });
      collect();
      if (progress) progress(events.fraction(), events.read());
    }
  };
  for (const auto& stamp : images) {
    feedEventsUntil(stamp.t_ns);
    const cv::Mat frame = io::readFrame(folder, stamp, cv::Size(cam.camera.width(), cam.camera.height()));
    feedImuUntil(stamp.t_ns);
    run([&] { frontend.addFrame(stamp.t_ns, frame); });
    collect();
    ++result.frames;
  }
  feedEventsUntil(std::nullopt);
  result.events = events_seen;
  result.events_kept = frontend.numEvents();
  result.reconstructed_frames = frontend.numReconstructedFrames();
  result.tracks = last_t.size();
  result.processing_s = busy;
  return result;
}

}  // namespace evio::experiments

#include "evio/experiments/sequence_video.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <unordered_map>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/media_module.h"
#include "evio/core/io/staged_folder.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/options.h"
#include "evio/experiments/sequence_info.h"

namespace evio::experiments {

namespace fs = std::filesystem;

void VideoOptions::validate() const {
  requireInRange("fps", fps, 1.0, 240.0);
  requireInRange("speed", speed, 1e-3, 1e3);
  requireInRange("window_s", window_s, 1e-5, 10.0);
  requireInRange("track_tail_s", track_tail_s, 0.0, 60.0);
  requireInRange("scale", scale, 1, 8);
}

namespace {

/// Events in time order, one chunk at a time, from events.h5 or events.txt.
class EventFeed {
 public:
  EventFeed(const std::string& file, int width, int height) {
    if (fs::path(file).filename() == "events.h5")
      h5_ = std::make_unique<io::EventH5Reader>(file, width, height);
    else
      txt_ = std::make_unique<io::EventTextReader>(file, io::SensorSize{width, height});
  }
  /// Moves every event with t ≤ t_ns into `window`.
  void takeUntil(TimeNs t_ns, std::deque<Event>& window) {
    while (true) {
      if (next_ >= chunk_.size()) {
        chunk_.clear();
        next_ = 0;
        if (done_ || !(h5_ ? h5_->next(chunk_, kChunk) : txt_->next(chunk_, kChunk))) {
          done_ = true;
          return;
        }
      }
      if (chunk_.t()[next_] > t_ns) return;
      window.push_back(chunk_[next_++]);
    }
  }

 private:
  static constexpr std::size_t kChunk = 1u << 16;
  std::unique_ptr<io::EventH5Reader> h5_;
  std::unique_ptr<io::EventTextReader> txt_;
  EventArray chunk_;
  std::size_t next_ = 0;
  bool done_ = false;
};

/// The latest position of each track, fed in file order.
class TrackFeed {
 public:
  explicit TrackFeed(const std::string& file) : reader_(file) { have_ = reader_.next(pending_); }
  void takeUntil(TimeNs t_ns) {
    while (have_ && pending_.t_ns <= t_ns) {
      auto& tail = tails_[pending_.id];
      tail.push_back(pending_);
      have_ = reader_.next(pending_);
    }
  }
  /// Drops samples older than t_ns − tail, and tracks with nothing left.
  void forget(TimeNs oldest_ns) {
    for (auto it = tails_.begin(); it != tails_.end();) {
      auto& tail = it->second;
      while (!tail.empty() && tail.front().t_ns < oldest_ns) tail.pop_front();
      it = tail.empty() ? tails_.erase(it) : std::next(it);
    }
  }
  const std::unordered_map<std::int64_t, std::deque<io::TrackSample>>& tails() const { return tails_; }

 private:
  io::TracksReader reader_;
  io::TrackSample pending_;
  bool have_ = false;
  std::unordered_map<std::int64_t, std::deque<io::TrackSample>> tails_;
};

/// A distinct colour per track id (golden-angle hue), BGR.
cv::Scalar trackColour(std::int64_t id) {
  const double hue = std::fmod(static_cast<double>(id) * 137.508, 360.0);
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue / 2.0, 220, 255)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return cv::Scalar(c[0], c[1], c[2]);
}

void drawTracks(cv::Mat& panel, const TrackFeed& tracks, int scale) {
  for (const auto& [id, tail] : tracks.tails()) {
    const cv::Scalar colour = trackColour(id);
    auto px = [scale](const io::TrackSample& s) {
      return cv::Point(static_cast<int>(std::lround((s.uv.x() + 0.5) * scale - 0.5)),
                       static_cast<int>(std::lround((s.uv.y() + 0.5) * scale - 0.5)));
    };
    for (std::size_t i = 1; i < tail.size(); ++i) cv::line(panel, px(tail[i - 1]), px(tail[i]), colour, 1, cv::LINE_AA);
    cv::circle(panel, px(tail.back()), 2 * scale, colour, 1, cv::LINE_AA);
  }
}

std::string chooseTracksFile(const std::string& folder, const std::string& option) {
  if (option == "none") return {};
  if (!option.empty()) {
    if (!fs::is_regular_file(option)) throw Error(option + ": no such tracks file");
    return option;
  }
  const fs::path truth = fs::path(folder) / "truth" / "tracks.txt";
  return fs::is_regular_file(truth) ? truth.string() : std::string();
}

/// Opens an encoder on `path` (through the media module): H.264 if this
/// OpenCV/FFmpeg has it, else MPEG-4 part 2.
std::unique_ptr<io::media::VideoEncoder> openEncoder(const std::string& path, const std::string& shown, double fps,
                                                     cv::Size size, std::string& codec) {
  const io::media::Api& media = io::media::api(shown);
  for (const char* fourcc : {"avc1", "mp4v"}) {
    std::unique_ptr<io::media::VideoEncoder> encoder(media.open_video(path, fourcc, fps, size.width, size.height));
    if (encoder) {
      codec = fourcc;
      return encoder;
    }
  }
  throw Error(shown + ": no video encoder could open it (OpenCV's FFmpeg backend with H.264 or MPEG-4)");
}

}  // namespace

VideoSummary writeSequenceVideo(const std::string& folder, const std::string& output, const VideoOptions& options,
                                const std::function<void(double)>& progress) {
  options.validate();
  const std::string ext = fs::path(output).extension().string();
  if (ext != ".mp4" && ext != ".avi") throw Error(output + ": the video must end in .mp4 or .avi");
  const SequenceInfo info = inspectSequence(folder);
  if (info.width <= 0 || info.height <= 0) throw Error(folder + ": the sensor size is unknown (no sensors.yaml, frames or events)");
  if (!info.events.present && !info.frames.present) throw Error(folder + ": neither events nor frames to show");

  VideoSummary summary;
  summary.tracks_file = chooseTracksFile(folder, options.tracks);
  const int s = options.scale;
  const cv::Size panel(info.width * s, info.height * s);
  summary.width = 2 * panel.width;
  summary.height = panel.height;

  const std::vector<io::ImageStamp> stamps =
      info.frames.present ? io::readImageList(folder) : std::vector<io::ImageStamp>{};
  std::optional<EventFeed> events;
  if (info.events.present) events.emplace(info.events.file, info.width, info.height);
  std::optional<TrackFeed> tracks;
  if (!summary.tracks_file.empty()) tracks.emplace(summary.tracks_file);

  TimeNs t_first = std::numeric_limits<TimeNs>::max(), t_last = std::numeric_limits<TimeNs>::min();
  for (const StreamStats* st : {&info.events, &info.frames}) {
    if (!st->present) continue;
    t_first = std::min(t_first, st->t_first_ns);
    t_last = std::max(t_last, st->t_last_ns);
  }
  const double step_s = options.speed / options.fps;
  const std::size_t n_frames = 1 + static_cast<std::size_t>(std::floor(nsToSeconds(t_last - t_first) / step_s + 1e-9));

  io::StagedFiles staged(output);
  const std::string staged_path = staged.path(output);
  const std::unique_ptr<io::media::VideoEncoder> writer =
      openEncoder(staged_path, output, options.fps, cv::Size(summary.width, summary.height), summary.codec);
  const TimeNs window_ns = secondsToNs(options.window_s);
  const TimeNs tail_ns = secondsToNs(options.track_tail_s);
  std::deque<Event> window;
  std::size_t next_stamp = 0;
  cv::Mat frame_grey(info.height, info.width, CV_8UC1, cv::Scalar(64));
  cv::Mat video(summary.height, summary.width, CV_8UC3);
  for (std::size_t k = 0; k < n_frames; ++k) {
    const TimeNs t = t_first + secondsToNs(static_cast<double>(k) * step_s);
    // Left: the latest frame at or before t.
    while (next_stamp < stamps.size() && stamps[next_stamp].t_ns <= t)
      frame_grey = io::readFrame(folder, stamps[next_stamp++], cv::Size(info.width, info.height));
    // Right: the events of (t − window, t].
    cv::Mat change(info.height, info.width, CV_8UC1, cv::Scalar(128));
    if (events) {
      events->takeUntil(t, window);
      while (!window.empty() && window.front().t_ns <= t - window_ns) window.pop_front();
      for (const Event& e : window) change.at<std::uint8_t>(e.y, e.x) = e.positive ? 255 : 0;
      summary.events += window.size();
    }
    cv::Mat left = video(cv::Rect(0, 0, panel.width, panel.height));
    cv::Mat right = video(cv::Rect(panel.width, 0, panel.width, panel.height));
    cv::Mat scaled;
    cv::resize(frame_grey, scaled, panel, 0, 0, cv::INTER_NEAREST);
    cv::cvtColor(scaled, left, cv::COLOR_GRAY2BGR);
    cv::resize(change, scaled, panel, 0, 0, cv::INTER_NEAREST);
    cv::cvtColor(scaled, right, cv::COLOR_GRAY2BGR);
    if (tracks) {
      tracks->takeUntil(t);
      tracks->forget(t - tail_ns);
      drawTracks(left, *tracks, s);
      drawTracks(right, *tracks, s);
    }
    char text[128];
    std::snprintf(text, sizeof(text), "t = %.3f s   %.0f kev/s", nsToSeconds(t - t_first),
                  static_cast<double>(window.size()) / options.window_s / 1e3);
    cv::putText(video, text, cv::Point(6, 16 + 2 * s), cv::FONT_HERSHEY_SIMPLEX, 0.4 * s, cv::Scalar(0, 200, 255), 1,
                cv::LINE_AA);
    writer->write(video);
    ++summary.frames;
    if (progress) progress(static_cast<double>(k + 1) / static_cast<double>(n_frames));
  }
  writer->release();
  io::faultPoint(output);
  staged.publish();
  return summary;
}

}  // namespace evio::experiments

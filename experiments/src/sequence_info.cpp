#include "evio/experiments/sequence_info.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tum.h"

namespace evio::experiments {

namespace fs = std::filesystem;

double StreamStats::meanRateHz() const {
  const double d = durationS();
  return (count >= 2 && d > 0.0) ? static_cast<double>(count - 1) / d : 0.0;
}

double SequenceInfo::durationS() const {
  TimeNs lo = 0, hi = 0;
  bool any = false;
  for (const StreamStats* s : {&events, &imu, &frames, &groundtruth}) {
    if (!s->present || s->count == 0) continue;
    lo = any ? std::min(lo, s->t_first_ns) : s->t_first_ns;
    hi = any ? std::max(hi, s->t_last_ns) : s->t_last_ns;
    any = true;
  }
  return any ? nsToSeconds(hi - lo) : 0.0;
}

namespace {

/// Accumulates event counts, time range, max pixel and the peak rate over
/// fixed windows of `window_ns`.
struct EventAccumulator {
  TimeNs window_ns;
  StreamStats stats;
  std::uint64_t in_window = 0;
  TimeNs window_start = 0;
  std::uint64_t peak = 0;
  int max_x = -1, max_y = -1;

  void add(const EventArray& ev) {
    const auto& t = ev.t();
    for (std::size_t i = 0; i < ev.size(); ++i) {
      if (stats.count == 0) {
        stats.t_first_ns = t[i];
        window_start = t[i];
      }
      while (t[i] >= window_start + window_ns) {
        peak = std::max(peak, in_window);
        in_window = 0;
        window_start += window_ns;
        // Skip empty stretches in one step.
        if (t[i] >= window_start + window_ns)
          window_start += (t[i] - window_start) / window_ns * window_ns;
      }
      ++in_window;
      ++stats.count;
      stats.t_last_ns = t[i];
      max_x = std::max<int>(max_x, ev.x()[i]);
      max_y = std::max<int>(max_y, ev.y()[i]);
    }
  }
  std::uint64_t peakCount() const { return std::max(peak, in_window); }
};

std::string path(const std::string& folder, const char* name) { return (fs::path(folder) / name).string(); }

}  // namespace

SequenceInfo inspectSequence(const std::string& folder, const ProgressCallback& progress) {
  if (!fs::is_directory(folder)) throw Error::inFile(folder, 0, "not a sequence folder (no such directory)");
  SequenceInfo info;
  info.folder = folder;
  auto exists = [&](const char* name) { return fs::exists(path(folder, name)); };

  info.has_calib = exists("calib.txt");
  info.has_sensors_yaml = exists("sensors.yaml");
  info.has_scenario = exists("scenario.yaml");
  info.has_truth = fs::is_directory(path(folder, "truth"));
  for (const char* name : {"events.h5", "events.txt", "images.txt", "imu.txt", "groundtruth.txt",
                           "calib.txt", "sensors.yaml"})
    if (!exists(name)) info.missing.emplace_back(name);

  if (info.has_sensors_yaml) {
    const SensorRig rig = io::readSensorsYaml(path(folder, "sensors.yaml"));
    const CameraSensor* cam = rig.firstCamera(CameraRole::kEvent);
    if (!cam) cam = &rig.cameras.front();
    info.width = cam->camera.width();
    info.height = cam->camera.height();
    info.resolution_source = "sensors.yaml";
  }

  // Frames first: the first frame gives the resolution of a recorded sequence.
  if (exists("images.txt")) {
    const auto frames = io::readImageList(folder);
    info.frames.present = true;
    info.frames.file = path(folder, "images.txt");
    info.frames.count = frames.size();
    if (!frames.empty()) {
      info.frames.t_first_ns = frames.front().t_ns;
      info.frames.t_last_ns = frames.back().t_ns;
      if (info.width == 0) {
        const cv::Mat first = io::readFrame(folder, frames.front());
        info.width = first.cols;
        info.height = first.rows;
        info.resolution_source = "first frame";
      }
    }
  }

  EventAccumulator acc{TimeNs(info.peak_window_ms) * kNsPerMs, {}, 0, 0, 0, -1, -1};
  EventArray chunk;
  constexpr std::size_t kChunk = 1u << 20;
  if (exists("events.h5")) {
    io::EventH5Reader reader(path(folder, "events.h5"), info.width, info.height);
    acc.stats.file = reader.path();
    const double total = std::max<double>(1.0, static_cast<double>(reader.size()));
    while (reader.next(chunk, kChunk)) {
      acc.add(chunk);
      if (progress) progress(static_cast<double>(acc.stats.count) / total, acc.stats.count);
    }
  } else if (exists("events.txt")) {
    std::optional<io::SensorSize> sensor;
    if (info.width > 0) sensor = io::SensorSize{info.width, info.height};
    io::EventTextReader reader(path(folder, "events.txt"), sensor);
    acc.stats.file = path(folder, "events.txt");
    const double bytes = std::max<double>(1.0, static_cast<double>(fs::file_size(acc.stats.file)));
    while (true) {
      chunk.clear();
      if (!reader.next(chunk, kChunk)) break;
      acc.add(chunk);
      // ~22 bytes per line: an estimate for the progress line only.
      if (progress) progress(std::min(1.0, static_cast<double>(acc.stats.count) * 22.0 / bytes), acc.stats.count);
    }
  }
  if (!acc.stats.file.empty()) {
    info.events = acc.stats;
    info.events.present = true;
    info.peak_event_rate_hz = static_cast<double>(acc.peakCount()) * 1000.0 / info.peak_window_ms;
    if (info.width == 0 && acc.max_x >= 0) {
      info.width = acc.max_x + 1;
      info.height = acc.max_y + 1;
      info.resolution_source = "events (max x, y + 1)";
    }
  }

  if (exists("imu.txt")) {
    io::ImuTextReader reader(path(folder, "imu.txt"));
    info.imu.present = true;
    info.imu.file = path(folder, "imu.txt");
    ImuSample s;
    while (reader.next(s)) {
      if (info.imu.count == 0) info.imu.t_first_ns = s.t_ns;
      info.imu.t_last_ns = s.t_ns;
      ++info.imu.count;
    }
  }

  if (exists("groundtruth.txt")) {
    io::TumReader reader(path(folder, "groundtruth.txt"));
    info.groundtruth.present = true;
    info.groundtruth.file = path(folder, "groundtruth.txt");
    StampedPose p;
    Vec3 last = Vec3::Zero();
    while (reader.next(p)) {
      if (info.groundtruth.count == 0) info.groundtruth.t_first_ns = p.t_ns;
      else info.groundtruth_path_length_m += (p.pose.translation() - last).norm();
      last = p.pose.translation();
      info.groundtruth.t_last_ns = p.t_ns;
      ++info.groundtruth.count;
    }
  }
  return info;
}

namespace {

/// `v` with `decimals` digits after the point ('f') or `digits` significant ('g').
std::string fixed(int decimals, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*f", decimals, v);
  return buf;
}
std::string general(int digits, double v) {
  char buf[64];
  std::snprintf(buf, sizeof(buf), "%.*g", digits, v);
  return buf;
}

std::string streamLine(const char* name, const StreamStats& s, const char* unit) {
  if (!s.present) return std::string(name) + ": missing\n";
  return std::string(name) + ": " + std::to_string(s.count) + " " + unit + ", " + fixed(3, nsToSeconds(s.t_first_ns)) +
         " .. " + fixed(3, nsToSeconds(s.t_last_ns)) + " s (" + fixed(3, s.durationS()) + " s), " +
         fixed(1, s.meanRateHz()) + " Hz\n";
}

}  // namespace

std::string formatSequenceInfo(const SequenceInfo& info) {
  std::string out = "sequence:    " + info.folder + "\n";
  out += "duration:    " + fixed(3, info.durationS()) + " s\n";
  out += "resolution:  " + (info.width > 0 ? std::to_string(info.width) + "x" + std::to_string(info.height) : "unknown") +
         " (from " + info.resolution_source + ")\n";
  out += streamLine("events", info.events, "events");
  if (info.events.present)
    out += "             mean " + general(4, info.events.meanRateHz()) + " ev/s, peak " +
           general(4, info.peak_event_rate_hz) + " ev/s over " + std::to_string(info.peak_window_ms) + " ms windows\n";
  out += streamLine("imu", info.imu, "samples");
  out += streamLine("frames", info.frames, "frames");
  out += streamLine("groundtruth", info.groundtruth, "poses");
  if (info.groundtruth.present) out += "             path length " + fixed(3, info.groundtruth_path_length_m) + " m\n";
  out += std::string("calibration: ") + (info.has_sensors_yaml ? "sensors.yaml" : "") +
         (info.has_sensors_yaml && info.has_calib ? ", " : "") + (info.has_calib ? "calib.txt" : "") +
         (!info.has_sensors_yaml && !info.has_calib ? "missing" : "") + "\n";
  out += std::string("truth/:      ") + (info.has_truth ? "present" : "absent") + "\n";
  if (!info.missing.empty()) {
    out += "missing:     ";
    for (std::size_t i = 0; i < info.missing.size(); ++i) out += (i ? ", " : "") + info.missing[i];
    out += "\n";
  }
  return out;
}

namespace {
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof(buf), "\\u%04x", c);
      out += buf;
      continue;
    }
    out.push_back(c);
  }
  return out + "\"";
}

std::string jsonStream(const StreamStats& s) {
  return "{\"present\": " + std::string(s.present ? "true" : "false") + ", \"count\": " + std::to_string(s.count) +
         ", \"t_first_s\": " + fixed(9, nsToSeconds(s.t_first_ns)) + ", \"t_last_s\": " +
         fixed(9, nsToSeconds(s.t_last_ns)) + ", \"rate_hz\": " + general(6, s.meanRateHz()) + "}";
}
}  // namespace

std::string sequenceInfoJson(const SequenceInfo& info) {
  std::string missing = "[";
  for (std::size_t i = 0; i < info.missing.size(); ++i) missing += (i ? ", " : "") + jsonString(info.missing[i]);
  missing += "]";
  return "{\"folder\": " + jsonString(info.folder) + ", \"duration_s\": " + fixed(9, info.durationS()) +
         ", \"width\": " + std::to_string(info.width) + ", \"height\": " + std::to_string(info.height) +
         ", \"resolution_source\": " + jsonString(info.resolution_source) + ", \"events\": " + jsonStream(info.events) +
         ", \"peak_event_rate_hz\": " + general(6, info.peak_event_rate_hz) + ", \"imu\": " + jsonStream(info.imu) +
         ", \"frames\": " + jsonStream(info.frames) + ", \"groundtruth\": " + jsonStream(info.groundtruth) +
         ", \"groundtruth_path_length_m\": " + fixed(6, info.groundtruth_path_length_m) +
         ", \"missing\": " + missing + "}\n";
}

}  // namespace evio::experiments

#include "evio/bags/bag_export.h"

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>

#include "bag_file.h"
#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/staged_folder.h"
#include "export_sources.h"

namespace evio::bags {

namespace {

namespace fs = std::filesystem;

std::string inFolder(const std::string& folder, const char* name) { return (fs::path(folder) / name).string(); }

/// The topic of a kind: the override, or the default ("" = leave the kind out).
std::string topicFor(const BagExportOptions& options, TopicKind kind) {
  const auto o = options.topics.find(kind);
  return o != options.topics.end() ? o->second : std::string(defaultTopic(kind));
}

/// What the sequence says about its event camera.
struct EventCamera {
  std::string name = "cam0";
  int width = 0, height = 0;
  std::optional<io::CalibTxt> calib;
};

/// Sensor size of the events alone: the largest x and y plus one (as `evio info`).
void sizeFromEvents(const std::string& folder, EventCamera& cam) {
  EventArray chunk;
  int max_x = -1, max_y = -1;
  auto scan = [&] {
    for (std::size_t i = 0; i < chunk.size(); ++i) {
      max_x = std::max<int>(max_x, chunk.x()[i]);
      max_y = std::max<int>(max_y, chunk.y()[i]);
    }
    chunk.clear();
  };
  if (fs::exists(inFolder(folder, "events.txt"))) {
    io::EventTextReader reader(inFolder(folder, "events.txt"));
    while (reader.next(chunk, 1u << 16)) scan();
  } else {
    io::EventH5Reader reader(inFolder(folder, "events.h5"));
    if (reader.width() > 0) {
      cam.width = reader.width();
      cam.height = reader.height();
      return;
    }
    while (reader.next(chunk, 1u << 16)) scan();
  }
  if (max_x >= 0) cam.width = max_x + 1, cam.height = max_y + 1;
}

/// Name, size and calibration of the event camera: sensors.yaml, calib.txt,
/// else the first frame's size (the DAVIS reads frames and events off one
/// pixel array), else the events'.
EventCamera eventCamera(const std::string& folder, const std::optional<SensorRig>& rig, bool has_events) {
  EventCamera cam;
  if (rig) {
    const CameraSensor* c = rig->firstCamera(CameraRole::kEvent);
    if (!c) c = &rig->cameras.front();
    cam.name = c->name;
    cam.width = c->camera.width();
    cam.height = c->camera.height();
    try {
      cam.calib = io::calibTxtFromCamera(c->camera);
    } catch (const Error&) {
      // An equidistant camera: no CameraInfo, sensors.yaml carries it.
    }
  }
  if (fs::exists(inFolder(folder, "calib.txt"))) cam.calib = io::readCalibTxt(inFolder(folder, "calib.txt"));
  if (cam.width == 0 && fs::exists(inFolder(folder, "images.txt"))) {
    const auto stamps = io::readImageList(folder);
    if (!stamps.empty()) {
      const cv::Mat first = io::readFrame(folder, stamps.front());
      cam.width = first.cols;
      cam.height = first.rows;
    }
  }
  if (cam.width == 0 && has_events) sizeFromEvents(folder, cam);
  return cam;
}

/// The sources of the sequence's streams, in the order that breaks ties.
std::vector<std::unique_ptr<detail::ExportSource>> openSources(const std::string& folder, const EventCamera& cam,
                                                               const BagExportOptions& options, bool has_events) {
  std::vector<std::unique_ptr<detail::ExportSource>> sources;
  const std::string events = topicFor(options, TopicKind::kEvents);
  if (has_events && !events.empty())
    sources.push_back(std::make_unique<detail::EventSource>(events, folder, cam.width, cam.height,
                                                            secondsToNs(options.event_window_s),
                                                            options.max_events_per_message, cam.name));
  const std::string frames = topicFor(options, TopicKind::kFrames);
  if (fs::exists(inFolder(folder, "images.txt")) && !frames.empty())
    sources.push_back(std::make_unique<detail::FrameSource>(frames, folder, cam.name));
  const std::string imu = topicFor(options, TopicKind::kImu);
  if (fs::exists(inFolder(folder, "imu.txt")) && !imu.empty())
    sources.push_back(std::make_unique<detail::ImuSource>(imu, inFolder(folder, "imu.txt"), "imu"));
  const std::string poses = topicFor(options, TopicKind::kGroundTruth);
  if (fs::exists(inFolder(folder, "groundtruth.txt")) && !poses.empty())
    sources.push_back(std::make_unique<detail::PoseSource>(poses, inFolder(folder, "groundtruth.txt"), "world"));
  return sources;
}

/// The source with the earliest pending message (the first of equals), or nullptr.
detail::ExportSource* earliest(const std::vector<std::unique_ptr<detail::ExportSource>>& sources) {
  detail::ExportSource* best = nullptr;
  for (const auto& s : sources)
    if (!s->empty() && (!best || s->time() < best->time())) best = s.get();
  return best;
}

/// The temporary bag: removed unless renamed onto the target.
struct TemporaryBag {
  std::string path;
  io::InterruptCleanup cleanup;
  bool kept = false;
  explicit TemporaryBag(const std::string& target) : path(io::temporaryPathFor(target)), cleanup(path) {}
  ~TemporaryBag() {
    if (kept) return;
    std::error_code ec;
    fs::remove(path, ec);
  }
};

}  // namespace

void BagExportOptions::validate() const {
  if (compression != "none" && compression != "bz2" && compression != "lz4")
    throw Error("compression (--compression): '" + compression + "' is not none, bz2 or lz4");
  if (!(event_window_s >= 1e-6 && event_window_s <= 1.0)) {
    char text[64];
    std::snprintf(text, sizeof(text), "%g", event_window_s);
    throw Error("event_window_s (--event-window): " + std::string(text) + " s is outside [1e-6, 1] s");
  }
  if (max_events_per_message < 1 || max_events_per_message > 10'000'000)
    throw Error("max_events_per_message (--max-events-per-message): " + std::to_string(max_events_per_message) +
                " is outside [1, 10^7]");
}

BagExportSummary exportBag(const std::string& sequence, const std::string& bag_path, const BagExportOptions& options) {
  options.validate();
  if (!fs::is_directory(sequence)) throw Error(sequence + ": not a sequence folder (no such directory)");
  io::checkOutputFile(bag_path);
  std::optional<SensorRig> rig;
  std::string sensors_text;
  if (fs::exists(inFolder(sequence, "sensors.yaml"))) {
    sensors_text = io::readFile(inFolder(sequence, "sensors.yaml"));
    rig = io::parseSensorsYaml(sensors_text, inFolder(sequence, "sensors.yaml"));
  }
  const bool has_events = fs::exists(inFolder(sequence, "events.txt")) || fs::exists(inFolder(sequence, "events.h5"));
  const EventCamera cam = eventCamera(sequence, rig, has_events);
  auto sources = openSources(sequence, cam, options, has_events);
  if (sources.empty() && !rig && !cam.calib)
    throw Error(sequence + ": nothing to export (no events, images.txt, imu.txt, groundtruth.txt, calib.txt or "
                "sensors.yaml)");

  BagExportSummary summary;
  summary.width = cam.width;
  summary.height = cam.height;
  detail::silenceRosLogging();
  TemporaryBag tmp(bag_path);
  try {
    rosbag::Bag bag;
    bag.open(tmp.path, rosbag::bagmode::Write);
    bag.setCompression(options.compression == "bz2"   ? rosbag::compression::BZ2
                       : options.compression == "lz4" ? rosbag::compression::LZ4
                                                      : rosbag::compression::Uncompressed);
    // The rig first, at the sequence's first stamp.
    const detail::ExportSource* first = earliest(sources);
    const TimeNs t0 = first ? first->time() : 0;
    const ros::Time record0 = detail::rosTimeFromNs(std::max<TimeNs>(t0, 1));
    const std::string info_topic = topicFor(options, TopicKind::kCameraInfo);
    if (cam.calib && cam.width > 0 && !info_topic.empty()) {
      bag.write(info_topic, record0, detail::cameraInfoFromCalib(*cam.calib, cam.width, cam.height, t0, cam.name));
      summary.camera_info = true;
    }
    const std::string sensors_topic = topicFor(options, TopicKind::kSensors);
    if (rig && !sensors_topic.empty()) {
      RosString text;
      text.data = sensors_text;
      bag.write(sensors_topic, record0, text);
      summary.sensors_yaml = true;
    }
    while (detail::ExportSource* next = earliest(sources)) {
      try {
        next->write(bag);
      } catch (const Error& e) {
        throw Error(std::string(e.what()) + " (writing " + next->topic() + " of " + sequence + ")");
      }
    }
    bag.close();
  } catch (const Error&) {
    throw;  // names the sequence file it came from
  } catch (...) {
    detail::rethrowAsError(bag_path, "writing");
  }
  io::renameFile(tmp.path, bag_path);
  tmp.kept = true;
  for (const auto& s : sources) {
    if (auto* e = dynamic_cast<detail::EventSource*>(s.get())) {
      summary.events = e->events();
      summary.event_messages = e->written();
    } else if (dynamic_cast<detail::FrameSource*>(s.get())) {
      summary.frames = s->written();
    } else if (dynamic_cast<detail::ImuSource*>(s.get())) {
      summary.imu_samples = s->written();
    } else {
      summary.groundtruth_poses = s->written();
    }
  }
  return summary;
}

}  // namespace evio::bags

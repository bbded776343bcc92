// computeSequenceStats: reads a sequence folder for `evio stats` (sequence_stats.h).
#include "evio/experiments/sequence_stats.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <opencv2/core.hpp>

#include "evio/core/error.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/io/images_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/options.h"

namespace evio::experiments {

namespace fs = std::filesystem;

void SequenceStatsOptions::validate() const {
  // At least 1 µs (windows are whole nanoseconds), at most an hour.
  requireField(rate_window_s >= 1e-6 && rate_window_s <= 3600.0, "rate_window_s", "must be in [1e-6, 3600] s");
  requirePositive("burst_gap_s", burst_gap_s);
  requireNonNegative("isolation_window_s", isolation_window_s);
  requireField(width_px >= 0 && height_px >= 0, "width_px", "must be >= 0 (0: from the folder)");
  requireField((width_px == 0) == (height_px == 0), "height_px", "give both width_px and height_px, or neither");
}

double FrameStreamStats::rateHz() const {
  const double d = nsToSeconds(t_last_ns - t_first_ns);
  return count >= 2 && d > 0 ? static_cast<double>(count - 1) / d : 0.0;
}

namespace {

std::string path(const std::string& folder, const char* name) { return (fs::path(folder) / name).string(); }

EventStreamStats eventStats(const SequenceInfo& info, int width, int height, const SequenceStatsOptions& options,
                            const ProgressCallback& progress) {
  EventStatsAccumulator acc(width, height, options);
  EventArray chunk;
  constexpr std::size_t kChunk = 1u << 18;
  std::uint64_t done = 0;
  const double total = std::max<double>(1.0, static_cast<double>(info.events.count));
  auto step = [&] {
    acc.add(chunk);
    done += chunk.size();
    if (progress) progress(static_cast<double>(done) / total, done);
    chunk.clear();
  };
  if (fs::path(info.events.file).filename() == "events.h5") {
    io::EventH5Reader reader(info.events.file, width, height);
    while (reader.next(chunk, kChunk)) step();
  } else {
    io::EventTextReader reader(info.events.file, io::SensorSize{width, height});
    while (reader.next(chunk, kChunk)) step();
  }
  EventStreamStats s = acc.finish();
  s.file = info.events.file;
  return s;
}

/// What the folder says about the exposure (see FrameStreamStats::exposure_s).
std::string exposureNote(const std::string& folder, bool has_sensors_yaml) {
  if (!has_sensors_yaml) return "not recorded (no sensors.yaml)";
  const SensorRig rig = io::readSensorsYaml(path(folder, "sensors.yaml"));
  const CameraSensor* cam = rig.firstCamera(CameraRole::kFrame);
  if (!cam) return "not recorded (sensors.yaml has no frame camera)";
  std::string note = "not recorded per frame; sensors.yaml configures";
  for (const char* key : {"auto_exposure", "exposure_s"}) {
    const auto it = cam->parameters.find(key);
    char value[32];
    std::snprintf(value, sizeof(value), "%g", it == cam->parameters.end() ? 0.0 : it->second);
    if (it != cam->parameters.end()) note += std::string(" ") + key + " = " + value;
  }
  return note + " (the setting, before auto-exposure or first-frame metering)";
}

FrameStreamStats frameStats(const std::string& folder, bool has_sensors_yaml) {
  FrameStreamStats f;
  f.present = true;
  f.exposure_note = exposureNote(folder, has_sensors_yaml);
  const auto stamps = io::readImageList(folder);
  f.count = stamps.size();
  if (stamps.empty()) return f;
  f.t_first_ns = stamps.front().t_ns;
  f.t_last_ns = stamps.back().t_ns;
  std::vector<double> max_dn, white_dn;
  double sum_dn = 0.0, sum_at_max = 0.0, sum_near_white = 0.0, sum_laplacian = 0.0;
  cv::Size size;
  for (const auto& stamp : stamps) {
    const cv::Mat img = io::readFrame(folder, stamp, size);
    size = img.size();
    std::array<std::uint64_t, 256> h{};
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) ++h[img.at<std::uint8_t>(y, x)];
    int top = 255;
    while (top > 0 && h[static_cast<std::size_t>(top)] == 0) --top;
    max_dn.push_back(top);
    const double n = static_cast<double>(img.total());
    sum_at_max += static_cast<double>(h[static_cast<std::size_t>(top)]) / n;
    std::size_t white = 255;  // largest DN with h ≥ 0.5 % of n, in integers: 200·h ≥ n
    while (white > 0 && 200 * h[white] < img.total()) --white;
    white_dn.push_back(static_cast<double>(white));
    std::uint64_t near = 0;
    for (std::size_t v = white >= 10 ? white - 10 : 0; v < 256; ++v) near += h[v];
    sum_near_white += static_cast<double>(near) / n;
    for (std::size_t v = 0; v < 256; ++v) {
      f.histogram[v] += h[v];
      sum_dn += static_cast<double>(v * h[v]);
    }
    // Laplacian variance over the interior, in integers (exact).
    std::int64_t s1 = 0, s2 = 0, m = 0;
    for (int y = 1; y + 1 < img.rows; ++y)
      for (int x = 1; x + 1 < img.cols; ++x) {
        const auto at = [&](int yy, int xx) { return static_cast<std::int64_t>(img.at<std::uint8_t>(yy, xx)); };
        const std::int64_t l = at(y, x - 1) + at(y, x + 1) + at(y - 1, x) + at(y + 1, x) - 4 * at(y, x);
        s1 += l;
        s2 += l * l;
        ++m;
      }
    if (m > 0) {
      const double mean = static_cast<double>(s1) / static_cast<double>(m);
      sum_laplacian += static_cast<double>(s2) / static_cast<double>(m) - mean * mean;
    }
  }
  f.width = size.width;
  f.height = size.height;
  const double frames = static_cast<double>(f.count);
  const double pixels = frames * static_cast<double>(size.area());
  f.brightness_mean_dn = sum_dn / pixels;
  f.fraction_at_0 = static_cast<double>(f.histogram[0]) / pixels;
  f.fraction_at_255 = static_cast<double>(f.histogram[255]) / pixels;
  f.max_dn = quantilesOf(std::move(max_dn));
  f.fraction_at_max = sum_at_max / frames;
  f.white_level_dn = quantilesOf(std::move(white_dn));
  f.fraction_near_white = sum_near_white / frames;
  f.laplacian_variance_dn2 = sum_laplacian / frames;
  return f;
}

}  // namespace

SequenceStats computeSequenceStats(const std::string& folder, const SequenceStatsOptions& options,
                                   const ProgressCallback& progress) {
  options.validate();
  const SequenceInfo info = inspectSequence(folder);
  if (!info.events.present && !info.frames.present)
    throw Error::inFile(folder, 0, "no events (events.h5 or events.txt) and no frames (images.txt): nothing to measure");
  if (info.events.count == 0 && info.frames.count == 0)
    throw Error::inFile(folder, 0, "the event and frame files hold no events and no frames: nothing to measure");
  SequenceStats stats;
  stats.folder = folder;
  stats.options = options;
  stats.width = options.width_px > 0 ? options.width_px : info.width;
  stats.height = options.height_px > 0 ? options.height_px : info.height;
  stats.resolution_source = options.width_px > 0 ? "options" : info.resolution_source;
  if (info.events.present) stats.events = eventStats(info, stats.width, stats.height, options, progress);
  if (info.frames.present) stats.frames = frameStats(folder, info.has_sensors_yaml);
  return stats;
}

}  // namespace evio::experiments

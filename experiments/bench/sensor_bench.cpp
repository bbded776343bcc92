// Event generation given rendered samples: pixel updates per second through
// EventCamera (simulator/event_camera.h). Run, on an otherwise idle machine:
//
//   <build>/experiments/bench/evio_sensor_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// Input: 32 radiance images of 640×480 (the DVXplorer preset's resolution)
// of an HDR texture (radiance e^-2 … e^3 W/(m²·sr)) translating by
// speed10 / 10 px per sample (0.1 px: ≈ 3 % of the pixels fire per sample;
// 0.5 px: ≈ 14 %, L changing by ≈ λ C = 0.1 per sample as under adaptive
// sampling), played forward then backward so the motion stays continuous;
// one sample per millisecond. They are made once per speed before the first
// benchmark that uses them; the rendering is not timed.
//
// Benchmarks:
//   BM_EventCameraUpdate/<model>/<threads>/<speed10>  whole-image update(); model 0 =
//       ideal pixel (thresholds with mismatch only), 1 = the full DVXplorer
//       preset (photoreceptor low-pass, refractory, leak, shot and hot-pixel
//       noise).
//   BM_EventCameraPerPixel/<model>/<speed10>  the adaptive path: updatePixels()
//       with every pixel's index, then emit(), one thread.
// Counters: pixel_updates_per_s (pixels · samples per second of wall time),
// events_per_update (events emitted per whole-image sample), peak_rss_MB
// (VmHWM of the process, input images included: 39 MB) and state_MB (the
// camera's per-pixel state).

#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "evio/simulator/event_camera.h"
#include "evio/simulator/event_sensor_preset.h"

namespace {

using evio::simulator::EventCamera;

constexpr int kWidth = 640, kHeight = 480, kFrames = 32;

double procStatusMb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  return 0.0;
}

/// The input images for a texture speed of speed10 / 10 px per sample.
const std::vector<std::vector<float>>& frames(std::int64_t speed10) {
  static std::map<std::int64_t, std::vector<std::vector<float>>> cache;
  auto& out = cache[speed10];
  if (out.empty()) {
    out.assign(kFrames, std::vector<float>(static_cast<std::size_t>(kWidth * kHeight)));
    for (int k = 0; k < kFrames; ++k)
      for (int y = 0; y < kHeight; ++y)
        for (int x = 0; x < kWidth; ++x) {
          const double u = x - 0.1 * static_cast<double>(speed10) * k;
          const double l = 0.5 + 1.5 * std::sin(0.11 * u + 0.3) * std::sin(0.07 * y) +
                           1.0 * std::sin(0.031 * u - 0.05 * y + 1.0);
          out[static_cast<std::size_t>(k)][static_cast<std::size_t>(y * kWidth + x)] = static_cast<float>(std::exp(l));
        }
  }
  return out;
}

/// Frame index of sample s: 0, 1, …, 31, 30, …, 1, 0, 1, …
int frameOf(std::int64_t s) {
  const auto period = static_cast<std::int64_t>(2 * (kFrames - 1));
  const auto p = s % period;
  return static_cast<int>(p < kFrames ? p : period - p);
}

EventCamera::Options model(std::int64_t m) {
  if (m == 0) return EventCamera::Options{};
  return evio::simulator::loadEventSensorPreset(std::string(EVIO_SIMULATOR_PRESET_DIR) + "/dvxplorer.yaml").event_camera;
}

void BM_EventCameraUpdate(benchmark::State& state) {
  const auto& images = frames(state.range(2));
  EventCamera::Options o = model(state.range(0));
  o.threads = static_cast<int>(state.range(1));
  EventCamera cam(kWidth, kHeight, o, 1);
  evio::EventArray events;
  std::vector<evio::simulator::EventLabel> labels;
  std::int64_t s = 0;
  cam.update(0, images[0].data(), &events, &labels);
  std::size_t emitted = 0;
  for (auto _ : state) {
    ++s;
    events.clear();
    labels.clear();
    cam.update(s * evio::kNsPerMs, images[static_cast<std::size_t>(frameOf(s))].data(), &events, &labels);
    emitted += events.size();
    benchmark::DoNotOptimize(events.t().data());
  }
  const double pixels = static_cast<double>(kWidth) * kHeight;
  state.counters["pixel_updates_per_s"] =
      benchmark::Counter(pixels, benchmark::Counter::kIsIterationInvariantRate);
  state.counters["events_per_update"] = static_cast<double>(emitted) / static_cast<double>(state.iterations());
  state.counters["peak_rss_MB"] = procStatusMb("VmHWM");
  state.counters["state_MB"] = pixels * 48.0 / (1024.0 * 1024.0);
}
BENCHMARK(BM_EventCameraUpdate)
    ->ArgNames({"model", "threads", "speed10"})
    ->ArgsProduct({{0, 1}, {1, 2}, {1, 5}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

void BM_EventCameraPerPixel(benchmark::State& state) {
  const auto& images = frames(state.range(1));
  EventCamera cam(kWidth, kHeight, model(state.range(0)), 1);
  evio::EventArray events;
  std::vector<evio::simulator::EventLabel> labels;
  std::int64_t s = 0;
  cam.update(0, images[0].data(), &events, &labels);
  const std::size_t n = cam.pixelCount();
  std::vector<std::uint32_t> indices(n);
  for (std::size_t i = 0; i < n; ++i) indices[i] = static_cast<std::uint32_t>(i);
  for (auto _ : state) {
    ++s;
    events.clear();
    labels.clear();
    const float* img = images[static_cast<std::size_t>(frameOf(s))].data();
    const evio::TimeNs t = s * evio::kNsPerMs;
    cam.updatePixels(t, indices.data(), img, n);
    cam.emit(&events, &labels);
    benchmark::DoNotOptimize(events.t().data());
  }
  state.counters["pixel_updates_per_s"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["peak_rss_MB"] = procStatusMb("VmHWM");
}
BENCHMARK(BM_EventCameraPerPixel)
    ->ArgNames({"model", "speed10"})
    ->ArgsProduct({{0, 1}, {1}})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

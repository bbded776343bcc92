// Frontend throughput: events per second through EKLT on one core, with the
// time split by stage. Run, on an otherwise idle machine:
//
//   <build>/experiments/bench/evio_frontend_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// The scene is a synthetic analogue of the Event-Camera Dataset's
// poster_6dof at the DAVIS240 resolution (240×180): a dense analytic texture
// of Gaussian blobs (tests/support/synthetic_events.h) moving
// rigidly (translation 60 px/s plus rotation 0.6 rad/s about the image
// centre), events from log-intensity thresholding with C = 0.2, frames at
// 20 Hz. It is generated once (a few seconds) before the first benchmark.
//
// Counters: events_per_s (events through the tracker per second of wall
// time), events_per_cpu_s (per second of this thread's CPU time, robust on a
// loaded machine), share_* (fraction of the tracker's time in event lookup+splatting,
// optimisation, Harris detection, bootstrap KLT, the rest of frame
// handling), batches_per_s, iters_per_batch, alive (mean live features at
// frames), peak_rss_MB and rss_start_MB (process memory, the data set
// included in both).

#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/estimator/frontend/eklt_tracker.h"
#include "evio/estimator/frontend/event_prefilter.h"
#include "frontend_dataset.h"

namespace {

using evio::EventArray;
using evio::TimeNs;

using evio::bench::frontendDataset;
using evio::bench::kHeight;
using evio::bench::kWidth;
using evio::bench::kContrast;

double procStatusMb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  return 0.0;
}

evio::Camera camera() {
  return evio::Camera::create("pinhole", kWidth, kHeight, evio::Vec4(200, 200, 119.5, 89.5), evio::VecX());
}

/// Runs EKLT over the whole data set; args: features, solver (0 lm, 1 ceres),
/// refractory period in ms, random keep-one-in r.
void BM_Eklt(benchmark::State& state) {
  const evio::bench::FrontendDataset& d = frontendDataset();
  std::ofstream("/proc/self/clear_refs") << "5";
  const double rss_start = procStatusMb("VmRSS");
  evio::estimator::EkltOptions options;
  options.max_features = static_cast<int>(state.range(0));
  options.min_features = options.max_features;
  options.solver = state.range(1) == 0 ? "lm" : "ceres";
  options.batch_contrast_threshold = kContrast;
  options.harris_quality_level = 0.01;  // enough corners for 45 features on this texture
  evio::estimator::EventPrefilterOptions filter_options;
  filter_options.refractory_period_s = 1e-3 * static_cast<double>(state.range(2));
  filter_options.random_keep_one_in = static_cast<int>(state.range(3));
  evio::estimator::EkltTiming total;
  double alive_sum = 0.0;
  std::uint64_t frames = 0, events = 0;
  EventArray filtered;
  timespec cpu0{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu0);
  for (auto _ : state) {
    evio::estimator::EkltTracker tracker(options, camera());
    evio::estimator::EventPrefilter prefilter(filter_options, kWidth, kHeight);
    evio::estimator::TrackPoints points;
    std::size_t next = 0;
    for (std::size_t f = 0; f < d.frames.size(); ++f) {
      const std::size_t end = d.events.lowerBound(d.frame_t_ns[f]);
      if (filter_options.passThrough()) {
        tracker.addEvents(d.events, next, end);
      } else {
        prefilter.filter(d.events, next, end, &filtered);
        tracker.addEvents(filtered);
      }
      events += end - next;
      next = end;
      tracker.addFrame(d.frame_t_ns[f], d.frames[f]);
      alive_sum += static_cast<double>(tracker.numAlive());
      ++frames;
      points.clear();
      tracker.drainTrackPoints(points);
      benchmark::DoNotOptimize(points.data());
    }
    const auto& t = tracker.timing();
    total.events_s += t.events_s;
    total.optimisation_s += t.optimisation_s;
    total.detection_s += t.detection_s;
    total.bootstrap_s += t.bootstrap_s;
    total.frame_s += t.frame_s;
    total.optimisations += t.optimisations;
    total.solver_iterations += t.solver_iterations;
  }
  timespec cpu1{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &cpu1);
  const double cpu_s = static_cast<double>(cpu1.tv_sec - cpu0.tv_sec) + 1e-9 * static_cast<double>(cpu1.tv_nsec - cpu0.tv_nsec);
  const double busy = total.events_s + total.frame_s;
  state.counters["events_per_s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
  state.counters["events_per_cpu_s"] = static_cast<double>(events) / cpu_s;
  state.counters["share_splat"] = total.splattingS() / busy;
  state.counters["share_optimise"] = total.optimisation_s / busy;
  state.counters["share_detect"] = total.detection_s / busy;
  state.counters["share_bootstrap"] = total.bootstrap_s / busy;
  state.counters["share_frame_other"] = (total.frame_s - total.detection_s - total.bootstrap_s) / busy;
  state.counters["batches_per_s"] =
      benchmark::Counter(static_cast<double>(total.optimisations), benchmark::Counter::kIsRate);
  state.counters["iters_per_batch"] =
      total.optimisations > 0 ? static_cast<double>(total.solver_iterations) / static_cast<double>(total.optimisations) : 0.0;
  state.counters["alive"] = frames > 0 ? alive_sum / static_cast<double>(frames) : 0.0;
  state.counters["events_in_data"] = static_cast<double>(d.events.size());
  state.counters["peak_rss_MB"] = procStatusMb("VmHWM");
  state.counters["rss_start_MB"] = rss_start;
}

BENCHMARK(BM_Eklt)
    ->ArgNames({"features", "ceres", "refractory_ms", "keep_one_in"})
    ->Args({45, 0, 0, 1})
    ->Args({15, 0, 0, 1})
    ->Args({45, 0, 10, 1})
    ->Args({45, 0, 0, 2})
    ->Args({45, 1, 0, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

// HASTE throughput: events per second through the HASTE tracker on one core,
// and per feature. Run, on an otherwise idle machine:
//
//   <build>/experiments/bench/evio_haste_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// The data set is the one of evio_frontend_bench (EKLT), so the two compare:
// a synthetic poster_6dof analogue at 240×180, Gaussian-blob texture moving
// rigidly (50, −33) px/s plus 0.6 rad/s about the image centre, events from
// log-intensity thresholding with C = 0.2, frames at 20 Hz (features seeded
// at their Harris corners, as HASTE-VIO does).
//
// Counters: events_per_s (events through the tracker per second of wall
// time), events_per_cpu_s (per second of this thread's CPU time),
// updates_per_cpu_s ((event, feature) score updates per CPU second: the
// events per second one feature can take, the unit the HASTE papers
// report), updates_per_event, alive (mean live features at frames), jumps_per_s.

#include <benchmark/benchmark.h>

#include <time.h>

#include <string>
#include <vector>

#include "evio/core/camera/camera.h"
#include "evio/estimator/frontend/haste_tracker.h"
#include "frontend_dataset.h"

namespace {

using evio::EventArray;
using evio::TimeNs;

using evio::bench::frontendDataset;
using evio::bench::kHeight;
using evio::bench::kWidth;

using evio::bench::threadCpuSeconds;

const char* const kVariants[] = {"haste_correlation", "haste_correlation_star", "haste_difference",
                                 "haste_difference_star"};

/// Runs HASTE over the whole data set; args: variant index (kVariants), features.
void BM_Haste(benchmark::State& state) {
  const evio::bench::FrontendDataset& d = frontendDataset();
  evio::estimator::HasteOptions options;
  options.variant = kVariants[state.range(0)];
  options.max_features = static_cast<int>(state.range(1));
  options.min_features = options.max_features;
  options.harris_quality_level = 0.01;  // enough corners for 45 features on this texture (as the EKLT bench)
  const evio::Camera camera =
      evio::Camera::create("pinhole", kWidth, kHeight, evio::Vec4(200, 200, 119.5, 89.5), evio::VecX());
  std::uint64_t events = 0, updates = 0, jumps = 0, frames = 0;
  double alive_sum = 0.0;
  const double cpu0 = threadCpuSeconds();
  for (auto _ : state) {
    evio::estimator::HasteTracker tracker(options, camera);
    evio::estimator::TrackPoints points;
    std::size_t next = 0;
    for (std::size_t f = 0; f < d.frames.size(); ++f) {
      const std::size_t end = d.events.lowerBound(d.frame_t_ns[f]);
      tracker.addEvents(d.events, next, end);
      events += end - next;
      next = end;
      tracker.addFrame(d.frame_t_ns[f], d.frames[f]);
      alive_sum += static_cast<double>(tracker.numAlive());
      ++frames;
      points.clear();
      tracker.drainTrackPoints(points);
      benchmark::DoNotOptimize(points.data());
    }
    updates += tracker.counters().feature_updates;
    jumps += tracker.counters().jumps;
  }
  const double cpu_s = threadCpuSeconds() - cpu0;
  state.counters["events_per_s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
  state.counters["events_per_cpu_s"] = static_cast<double>(events) / cpu_s;
  state.counters["updates_per_cpu_s"] = static_cast<double>(updates) / cpu_s;
  state.counters["updates_per_event"] = static_cast<double>(updates) / static_cast<double>(events);
  state.counters["jumps_per_s"] = benchmark::Counter(static_cast<double>(jumps), benchmark::Counter::kIsRate);
  state.counters["alive"] = frames > 0 ? alive_sum / static_cast<double>(frames) : 0.0;
  state.counters["events_in_data"] = static_cast<double>(d.events.size());
}

BENCHMARK(BM_Haste)
    ->ArgNames({"variant", "features"})
    ->Args({3, 45})
    ->Args({2, 45})
    ->Args({1, 45})
    ->Args({0, 45})
    ->Args({3, 15})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

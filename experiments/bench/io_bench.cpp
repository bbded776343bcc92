// Event file I/O benchmarks (core/io). Run, on an otherwise idle machine:
//
//   <build>/experiments/bench/evio_io_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// Every benchmark reports events/s (items_per_second) and the process's peak
// resident memory during the benchmark (peak_rss_MB, with the resident memory
// when it started in rss_start_MB). Files go to a temporary folder removed at
// exit. Layout of this file: shared helpers first (event generator, memory
// counters, scratch folder), then one section per format; append new formats
// (e.g. BM_EventsTxt*) as new sections at the end.

#include <benchmark/benchmark.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <string>
#include <tuple>
#include <vector>

#include "evio/core/event.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/io/events_txt.h"
#include "evio/core/random_stream.h"

namespace {

// ---------------------------------------------------------------------------
// Shared helpers
// ---------------------------------------------------------------------------

/// Events per benchmark file: 2^24 = 16.8 M, about 16.8 s at 1 Mev/s.
constexpr std::size_t kBenchEvents = std::size_t{1} << 24;
constexpr int kSensorWidth = 640;
constexpr int kSensorHeight = 480;

/// A deterministic, realistic event stream for benchmarks: Poisson arrivals
/// at `rate_hz` (sorted ns times with sub-µs parts), 90 % of the events on 64
/// edge points drifting across a 640x480 sensor (spatial locality like real
/// scenes, which matters for compression), 10 % uniform background noise,
/// random polarity. Same seed => same events.
class EventGenerator {
 public:
  explicit EventGenerator(std::uint64_t seed, double rate_hz = 1e6)
      : rng_(seed, "io_bench events"), rate_hz_(rate_hz) {
    for (Edge& e : edges_) e = randomEdge();
  }

  /// Replaces `out` by the next `n` events.
  void next(evio::EventArray& out, std::size_t n) {
    out.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      t_ns_ += static_cast<evio::TimeNs>(rng_.exponential(rate_hz_) * 1e9);
      double x = 0.0, y = 0.0;
      if (rng_.bernoulli(0.1)) {
        x = rng_.uniform(0.0, kSensorWidth);
        y = rng_.uniform(0.0, kSensorHeight);
      } else {
        Edge& e = edges_[rng_.uniformInt(edges_.size())];
        const double dt_s = static_cast<double>(t_ns_ - e.t_ns) * 1e-9;
        e.t_ns = t_ns_;
        e.x += e.vx * dt_s;
        e.y += e.vy * dt_s;
        if (e.x < 0 || e.x >= kSensorWidth || e.y < 0 || e.y >= kSensorHeight) e = randomEdge();
        const double s = rng_.uniform(-8.0, 8.0);  // along the edge
        x = e.x + s * e.dir_x + rng_.normal(0.0, 0.7);
        y = e.y + s * e.dir_y + rng_.normal(0.0, 0.7);
      }
      out.t()[i] = t_ns_;
      out.x()[i] = static_cast<std::uint16_t>(std::clamp(x, 0.0, kSensorWidth - 1.0));
      out.y()[i] = static_cast<std::uint16_t>(std::clamp(y, 0.0, kSensorHeight - 1.0));
      out.p()[i] = rng_.bernoulli(0.5) ? 1 : 0;
    }
  }

 private:
  struct Edge {
    double x, y, vx, vy, dir_x, dir_y;
    evio::TimeNs t_ns;
  };
  Edge randomEdge() {
    const double a = rng_.uniform(0.0, 2.0 * std::numbers::pi);
    const double speed = rng_.uniform(20.0, 400.0);  // px/s
    return Edge{rng_.uniform(0.0, kSensorWidth), rng_.uniform(0.0, kSensorHeight),
                speed * std::cos(a),              speed * std::sin(a),
                -std::sin(a),                     std::cos(a),
                t_ns_};
  }

  evio::RandomStream rng_;
  double rate_hz_;
  evio::TimeNs t_ns_ = 1'700'000'000'000'000'000;  // a Unix time, like a recording
  std::array<Edge, 64> edges_{};
};

/// A value from /proc/self/status in MB ("VmHWM", "VmRSS"); 0 if unavailable.
double procStatusMb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  return 0.0;
}

/// Resets the peak-RSS mark (Linux >= 4.0) so VmHWM measures one benchmark.
void resetPeakRss() { std::ofstream("/proc/self/clear_refs") << "5"; }

/// Call at the start of a benchmark; reports the counters when destroyed.
class MemoryCounters {
 public:
  explicit MemoryCounters(benchmark::State& state) : state_(state) {
    resetPeakRss();
    start_mb_ = procStatusMb("VmRSS");
  }
  ~MemoryCounters() {
    state_.counters["peak_rss_MB"] = procStatusMb("VmHWM");
    state_.counters["rss_start_MB"] = start_mb_;
  }
  MemoryCounters(const MemoryCounters&) = delete;
  MemoryCounters& operator=(const MemoryCounters&) = delete;

 private:
  benchmark::State& state_;
  double start_mb_ = 0.0;
};

/// The scratch folder of this run, removed at exit.
const std::filesystem::path& scratchDir() {
  struct Dir {
    std::filesystem::path path = std::filesystem::temp_directory_path() /
                                 ("evio_io_bench_" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Dir dir;
  return dir.path;
}

// ---------------------------------------------------------------------------
// events.h5 (DSEC layout)
// ---------------------------------------------------------------------------

/// Benchmark arguments: {gzip level, log2(chunk events), checksum 0/1}.
evio::io::EventH5Options h5Options(const benchmark::State& state) {
  evio::io::EventH5Options opt;
  opt.compression_level = static_cast<int>(state.range(0));
  opt.chunk_events = std::uint64_t{1} << state.range(1);
  opt.checksum = state.range(2) != 0;
  opt.width = kSensorWidth;
  opt.height = kSensorHeight;
  return opt;
}

/// A file of kBenchEvents generator events written with `opt`, made once.
const std::string& h5File(const evio::io::EventH5Options& opt) {
  static std::map<std::tuple<int, std::uint64_t, bool>, std::string> files;
  const auto key = std::make_tuple(opt.compression_level, opt.chunk_events, opt.checksum);
  auto it = files.find(key);
  if (it != files.end()) return it->second;
  const std::string path = (scratchDir() / ("events_" + std::to_string(opt.compression_level) +
                                            "_" + std::to_string(opt.chunk_events) + "_" +
                                            std::to_string(opt.checksum) + ".h5"))
                               .string();
  EventGenerator gen(1);
  evio::io::EventH5Writer writer(path, opt);
  evio::EventArray block;
  for (std::size_t done = 0; done < kBenchEvents; done += block.size()) {
    gen.next(block, std::min<std::size_t>(1 << 16, kBenchEvents - done));
    writer.append(block);
  }
  writer.close();
  return files.emplace(key, path).first->second;
}

void setFileCounters(benchmark::State& state, const std::string& path) {
  state.counters["bytes_per_event"] =
      static_cast<double>(std::filesystem::file_size(path)) / static_cast<double>(kBenchEvents);
}

void BM_EventsH5Write(benchmark::State& state) {
  const evio::io::EventH5Options opt = h5Options(state);
  // A 2^20-event pool appended 16 times, each copy shifted in time.
  EventGenerator gen(2);
  evio::EventArray pool, block;
  gen.next(pool, std::size_t{1} << 20);
  const evio::TimeNs pool_span_ns = pool.t().back() - pool.t().front() + 1000;
  const std::string path = (scratchDir() / "write.h5").string();
  MemoryCounters memory(state);
  for (auto _ : state) {
    evio::io::EventH5Writer writer(path, opt);
    for (std::size_t done = 0; done < kBenchEvents; done += block.size()) {
      state.PauseTiming();
      const std::size_t at = done % pool.size();
      const auto copy = static_cast<evio::TimeNs>(done / pool.size());
      const auto from = [&](const auto& column) { return column.begin() + static_cast<std::ptrdiff_t>(at); };
      const std::ptrdiff_t m = std::ptrdiff_t{1} << 16;
      block.t().assign(from(pool.t()), from(pool.t()) + m);
      block.x().assign(from(pool.x()), from(pool.x()) + m);
      block.y().assign(from(pool.y()), from(pool.y()) + m);
      block.p().assign(from(pool.p()), from(pool.p()) + m);
      for (evio::TimeNs& t : block.t()) t += copy * pool_span_ns;
      state.ResumeTiming();
      writer.append(block);
    }
    writer.close();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBenchEvents));
  setFileCounters(state, path);
}

void BM_EventsH5ReadStream(benchmark::State& state) {
  const std::string& path = h5File(h5Options(state));
  const auto batch = static_cast<std::size_t>(state.range(3));
  evio::EventArray out;
  MemoryCounters memory(state);
  for (auto _ : state) {
    evio::io::EventH5Reader reader(path);
    std::size_t n = 0;
    while (reader.next(out, batch)) n += out.size();
    if (n != kBenchEvents) state.SkipWithError("wrong event count");
    benchmark::DoNotOptimize(out.t().data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBenchEvents));
  setFileCounters(state, path);
}

void BM_EventsH5ReadAll(benchmark::State& state) {
  const std::string& path = h5File(h5Options(state));
  MemoryCounters memory(state);
  for (auto _ : state) {
    const evio::EventArray ev = evio::io::readEventsH5(path);
    if (ev.size() != kBenchEvents) state.SkipWithError("wrong event count");
    benchmark::DoNotOptimize(ev.t().data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBenchEvents));
  setFileCounters(state, path);
}

/// Random 10 ms windows located through /ms_to_idx (items = events returned).
void BM_EventsH5ReadWindow(benchmark::State& state) {
  const std::string& path = h5File(h5Options(state));
  evio::io::EventH5Reader reader(path);
  evio::RandomStream rng(3, "io_bench windows");
  const double span = static_cast<double>(reader.tLastNs() - reader.tFirstNs() - 10'000'000);
  evio::EventArray out;
  std::int64_t events = 0;
  MemoryCounters memory(state);
  for (auto _ : state) {
    const evio::TimeNs t0 = reader.tFirstNs() + static_cast<evio::TimeNs>(rng.uniform() * span);
    reader.readWindow(t0, t0 + 10'000'000, out);
    events += static_cast<std::int64_t>(out.size());
  }
  state.SetItemsProcessed(events);
}

// {level, log2 chunk, checksum}: the default (0, 16, 1) first, then one
// parameter varied at a time.
const std::vector<std::vector<std::int64_t>> kH5Configs = {
    {0, 16, 1}, {0, 16, 0}, {0, 17, 1}, {0, 18, 1}, {1, 16, 1}, {4, 16, 1}};

void h5Configs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"gzip", "chunk_log2", "checksum"});
  for (const auto& a : kH5Configs) b->Args(a);
}
void h5StreamConfigs(benchmark::internal::Benchmark* b) {
  b->ArgNames({"gzip", "chunk_log2", "checksum", "batch"});
  for (auto a : kH5Configs) {
    a.push_back(std::int64_t{1} << 16);
    b->Args(a);
  }
  b->Args({0, 16, 1, std::int64_t{1} << 20});
}

BENCHMARK(BM_EventsH5Write)->Apply(h5Configs)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EventsH5ReadStream)
    ->Apply(h5StreamConfigs)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_EventsH5ReadAll)->Apply(h5Configs)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EventsH5ReadWindow)
    ->ArgNames({"gzip", "chunk_log2", "checksum"})
    ->Args({0, 16, 1})
    ->Args({0, 16, 0})
    ->Args({0, 17, 1})
    ->Args({1, 16, 1})
    ->Unit(benchmark::kMicrosecond)
    ->UseRealTime();

// ---------------------------------------------------------------------------
// events.txt (Event-Camera Dataset text)
// ---------------------------------------------------------------------------

/// Events in the text benchmarks: 2^22 = 4.2 M (a 90 MB file).
constexpr std::size_t kTextEvents = std::size_t{1} << 22;

/// A events.txt of kTextEvents generator events, made once.
const std::string& textFile() {
  static const std::string path = [] {
    const std::string p = (scratchDir() / "events.txt").string();
    EventGenerator gen(4);
    evio::io::EventTextWriter writer(p);
    evio::EventArray block;
    for (std::size_t done = 0; done < kTextEvents; done += block.size()) {
      gen.next(block, std::min<std::size_t>(1 << 16, kTextEvents - done));
      writer.append(block);
    }
    writer.close();
    return p;
  }();
  return path;
}

/// Streaming read with full validation (columns, numbers, time order,
/// pixels inside the 640x480 sensor), in batches of 2^16 events.
void BM_EventsTxtReadStream(benchmark::State& state) {
  const std::string& path = textFile();
  evio::EventArray out;
  MemoryCounters memory(state);
  for (auto _ : state) {
    evio::io::EventTextReader reader(path, evio::io::SensorSize{kSensorWidth, kSensorHeight});
    std::size_t n = 0;
    while (true) {
      out.clear();
      if (!reader.next(out, std::size_t{1} << 16)) break;
      n += out.size();
    }
    if (n != kTextEvents) state.SkipWithError("wrong event count");
    benchmark::DoNotOptimize(out.t().data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kTextEvents));
  state.counters["bytes_per_event"] =
      static_cast<double>(std::filesystem::file_size(path)) / static_cast<double>(kTextEvents);
}

void BM_EventsTxtWrite(benchmark::State& state) {
  EventGenerator gen(5);
  evio::EventArray events;
  gen.next(events, kTextEvents);
  const std::string path = (scratchDir() / "write.txt").string();
  MemoryCounters memory(state);
  for (auto _ : state) evio::io::writeEventsText(path, events);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kTextEvents));
}

BENCHMARK(BM_EventsTxtReadStream)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_EventsTxtWrite)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();

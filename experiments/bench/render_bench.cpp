// Renderer throughput (simulator/renderer.h) against a bare Embree loop on
// the same scenes. Run, on an otherwise idle machine:
//
//   <build>/experiments/bench/evio_render_bench --benchmark_repetitions=5
//       --benchmark_report_aggregates_only=true
//
// For each preset of scenes/presets and each resolution (240x180, 346x260,
// 640x480), with the preset's preview pose and a 60° pinhole camera:
//   BM_BareEmbree  primary ray + one occlusion ray (towards the first sun or
//                  point light) per hit pixel, nothing else: the same tiles,
//                  ray streams (rtcIntersect1M/rtcOccluded1M, coherent flag)
//                  and thread count as the renderer, no shading, no output;
//   BM_Render      the full renderer (radiance, depth, normal; no flow), into
//                  output images reused from frame to frame (its AVX2 path
//                  when the CPU has AVX2);
//   BM_RenderBaseline  the same with RendererOptions::avx2 off: the baseline
//                  x86-64 path, which renders the same bits.
// The benchmark argument is the thread count (1 and 2). Counters:
//   rays_per_s_per_core  camera + occlusion rays traced per second of process
//                        CPU time (CLOCK_PROCESS_CPUTIME_ID), i.e. per busy
//                        core; robust against other load on the machine;
//   renders_per_s        frames per second of wall-clock time;
//   peak_rss_MB          VmHWM of the process.
// BM_SceneBuild/<preset> reports the scene build time (generation, BVH,
// indirect light) as its wall time, and its parts as counters.

#include <benchmark/benchmark.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <time.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "evio/scenes/embree_util.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/render_job.h"
#include "evio/simulator/renderer.h"

namespace {

using evio::scenes::Scene;

const char* const kPresets[] = {"mars_terrain", "mars_yard", "lava_tube", "ec_poster", "ec_shapes", "ec_boxes"};
const int kResolutions[][2] = {{240, 180}, {346, 260}, {640, 480}};
const int kThreads[] = {1, 2};

/// A value from /proc/self/status in MB ("VmHWM", "VmRSS"); 0 if unavailable.
double procStatusMb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  return 0.0;
}

std::string presetPath(const std::string& name) { return std::string(EVIO_SCENE_PRESET_DIR) + "/" + name + ".yaml"; }

/// Scenes are built once per process and shared by the benchmarks.
const Scene& scene(const std::string& name) {
  static std::map<std::string, std::unique_ptr<Scene>> cache;
  auto& s = cache[name];
  if (!s) s = std::make_unique<Scene>(evio::scenes::loadSceneFile(presetPath(name)));
  return *s;
}

evio::Camera camera(int w, int h) {
  const double f = 0.5 * w / std::tan(30.0 * std::numbers::pi / 180.0);  // 60° horizontal
  return evio::PinholeCamera(w, h, evio::Vec4(f, f, 0.5 * (w - 1), 0.5 * (h - 1)));
}

/// The bare loop: tiles of 16 px, one coherent stream of camera rays, one of
/// occlusion rays towards the light for the rays that hit.
class BareLoop {
 public:
  BareLoop(const Scene& s, const evio::Camera& cam) : scene_(s), w_(cam.width()), h_(cam.height()) {
    bearings_.resize(static_cast<std::size_t>(w_ * h_));
    for (int y = 0; y < h_; ++y)
      for (int x = 0; x < w_; ++x) {
        evio::Vec3 b;
        cam.unproject(evio::Vec2(x, y), &b);
        bearings_[static_cast<std::size_t>(y * w_ + x)] = b.normalized().cast<float>();
      }
    for (const auto& l : s.description().options.lights) {
      if (l.type == "sun") {
        sun_ = true;
        light_ = evio::scenes::sunDirection(l.azimuth_deg, l.elevation_deg).cast<float>();
        break;
      }
      if (l.type == "point" || l.type == "spot") {
        light_ = l.position_m.cast<float>();
        break;
      }
    }
  }

  /// Traces one frame; returns the number of rays.
  std::uint64_t run(const evio::Pose& T_W_C, int threads) const {
    const int t = 16, tiles_x = (w_ + t - 1) / t, tiles = tiles_x * ((h_ + t - 1) / t);
    std::vector<std::uint64_t> rays(static_cast<std::size_t>(tiles), 0);
    const Eigen::Matrix3f R = T_W_C.rotation().cast<float>();
    const Eigen::Vector3f org = T_W_C.translation().cast<float>();
    tbb::task_arena arena(threads);
    arena.execute([&] {
      tbb::parallel_for(tbb::blocked_range<int>(0, tiles, 1), [&](const tbb::blocked_range<int>& r) {
        for (int k = r.begin(); k != r.end(); ++k) {
          const int x0 = (k % tiles_x) * t, y0 = (k / tiles_x) * t;
          const int x1 = std::min(x0 + t, w_), y1 = std::min(y0 + t, h_);
          std::vector<RTCRayHit> rh;
          rh.reserve(static_cast<std::size_t>(t * t));
          for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) {
              RTCRayHit q;
              evio::scenes::setRayHit(q, org, R * bearings_[static_cast<std::size_t>(y * w_ + x)]);
              rh.push_back(q);
            }
          RTCIntersectContext ctx = evio::scenes::intersectContext(true);
          rtcIntersect1M(scene_.embree(), &ctx, rh.data(), static_cast<unsigned>(rh.size()), sizeof(RTCRayHit));
          std::vector<RTCRay> shadow;
          shadow.reserve(rh.size());
          for (const RTCRayHit& q : rh) {
            if (q.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
            const Eigen::Vector3f d(q.ray.dir_x, q.ray.dir_y, q.ray.dir_z);
            const Eigen::Vector3f p = org + (q.ray.tfar * 0.9999f) * d;
            RTCRay s;
            if (sun_) {
              evio::scenes::setRay(s, p, light_);
            } else {
              const Eigen::Vector3f to = light_ - p;
              evio::scenes::setRay(s, p, to.normalized(), 0.0f, to.norm());
            }
            shadow.push_back(s);
          }
          if (!shadow.empty())
            rtcOccluded1M(scene_.embree(), &ctx, shadow.data(), static_cast<unsigned>(shadow.size()), sizeof(RTCRay));
          rays[static_cast<std::size_t>(k)] = rh.size() + shadow.size();
        }
      });
    });
    std::uint64_t total = 0;
    for (auto n : rays) total += n;
    return total;
  }

 private:
  const Scene& scene_;
  int w_, h_;
  std::vector<Eigen::Vector3f> bearings_;
  bool sun_ = false;
  Eigen::Vector3f light_ = Eigen::Vector3f::UnitZ();
};

/// Process CPU time in seconds (all threads).
double processCpuS() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

void report(benchmark::State& state, double rays, double cpu_s) {
  state.counters["rays_per_s_per_core"] = rays / cpu_s;
  state.counters["renders_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()),
                                                       benchmark::Counter::kIsRate);
  state.counters["peak_rss_MB"] = procStatusMb("VmHWM");
}

void bareEmbree(benchmark::State& state, std::string preset, int w, int h) {
  const int threads = static_cast<int>(state.range(0));
  const Scene& s = scene(preset);
  const BareLoop loop(s, camera(w, h));
  const evio::Pose T = evio::simulator::previewPose(s.description());
  double rays = 0.0;
  const double cpu0 = processCpuS();
  for (auto _ : state) rays += static_cast<double>(loop.run(T, threads));
  report(state, rays, processCpuS() - cpu0);
}

void renderWith(benchmark::State& state, const std::string& preset, int w, int h, bool avx2) {
  const int threads = static_cast<int>(state.range(0));
  const Scene& s = scene(preset);
  evio::simulator::RendererOptions o;
  o.threads = threads;
  o.avx2 = avx2;
  const evio::simulator::Renderer renderer(s, camera(w, h), o);
  const evio::Pose T = evio::simulator::previewPose(s.description());
  double rays = 0.0;
  const double cpu0 = processCpuS();
  evio::simulator::RenderOutput out;  // reused from frame to frame, as the simulator does
  for (auto _ : state) {
    evio::simulator::RenderStats stats;
    renderer.render(T, nullptr, &out, &stats);
    benchmark::DoNotOptimize(out.radiance.data);
    rays += static_cast<double>(stats.camera_rays + stats.shadow_rays);
  }
  report(state, rays, processCpuS() - cpu0);
}

void render(benchmark::State& state, std::string preset, int w, int h) { renderWith(state, preset, w, h, true); }
void renderBaseline(benchmark::State& state, std::string preset, int w, int h) {
  renderWith(state, preset, w, h, false);
}

void sceneBuild(benchmark::State& state, std::string preset) {
  const auto d = evio::scenes::loadSceneFile(presetPath(preset));
  evio::scenes::SceneStats stats;
  for (auto _ : state) {
    const Scene s(d);
    stats = s.stats();
  }
  state.counters["generate_s"] = stats.generate_s;
  state.counters["bvh_s"] = stats.bvh_s;
  state.counters["indirect_s"] = stats.indirect_s;
  state.counters["triangles"] = static_cast<double>(stats.triangles);
  state.counters["peak_rss_MB"] = procStatusMb("VmHWM");
}

const int kRegistered = [] {
  for (const char* p : kPresets)
    benchmark::RegisterBenchmark((std::string("BM_SceneBuild/") + p).c_str(), sceneBuild, std::string(p))
        ->Unit(benchmark::kMillisecond)
        ->Iterations(1)
        ->UseRealTime();
  for (const char* p : kPresets)
    for (const auto& r : kResolutions) {
      const std::string suffix = std::string("/") + p + "/" + std::to_string(r[0]) + "x" + std::to_string(r[1]);
      for (const int t : kThreads) {
        benchmark::RegisterBenchmark(("BM_BareEmbree" + suffix).c_str(), bareEmbree, std::string(p), r[0], r[1])
            ->Arg(t)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("BM_Render" + suffix).c_str(), render, std::string(p), r[0], r[1])
            ->Arg(t)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
        benchmark::RegisterBenchmark(("BM_RenderBaseline" + suffix).c_str(), renderBaseline, std::string(p), r[0], r[1])
            ->Arg(t)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
  return 0;
}();

}  // namespace

BENCHMARK_MAIN();

#include "evio/simulator/sequence_simulator.h"

#include <cmath>
#include <filesystem>
#include <sstream>

#include "evio/core/error.h"
#include "evio/core/io/atomic_file.h"
#include "evio/core/io/calib_txt.h"
#include "evio/core/io/imu_state_txt.h"
#include "evio/core/io/imu_txt.h"
#include "evio/core/io/range_txt.h"
#include "evio/core/io/sensors_yaml.h"
#include "evio/core/io/tracks_txt.h"
#include "evio/core/io/tum.h"
#include "evio/core/stopwatch.h"
#include "evio/scenes/scene.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/simulator/range_finder.h"
#include "evio/simulator/truth_tracks.h"
#include "render_loop.h"

namespace evio::simulator {

namespace fs = std::filesystem;

namespace {

std::string path(const std::string& folder, const std::string& name) { return (fs::path(folder) / name).string(); }

/// Stamps of a clock at rate_hz over [start, end]: start + round(k · 1e9 / rate_hz).
std::vector<TimeNs> clockStamps(TimeNs start, TimeNs end, double rate_hz) {
  std::vector<TimeNs> out;
  for (std::int64_t k = 0;; ++k) {
    const TimeNs t = start + static_cast<TimeNs>(std::llround(static_cast<double>(k) * 1e9 / rate_hz));
    if (t > end) break;
    out.push_back(t);
  }
  return out;
}

/// groundtruth.txt (T_W_E), imu.txt and truth/imu_state.txt.
void writeMotion(const Scenario& s, const std::string& folder, SimulationStats* stats) {
  const ContinuousTrajectory& trajectory = *s.trajectory;
  const Pose T_B_E = s.T_B_E();
  io::TumWriter gt(path(folder, "groundtruth.txt"),
                   {"pose of the event camera E in the world W (T_W_E); t px py pz qx qy qz qw"});
  for (const TimeNs t : clockStamps(s.start_ns, s.end_ns, s.options.output.groundtruth_rate_hz)) {
    gt.append({t, trajectory.evaluate(t).T_W_B * T_B_E});
    ++stats->groundtruth_poses;
  }
  gt.close();
  stats->files.push_back(path(folder, "groundtruth.txt"));

  io::ImuTextWriter imu(path(folder, "imu.txt"));
  io::ImuStateWriter state(path(folder, "truth/imu_state.txt"),
                           {"true IMU state at each imu.txt sample (true time)",
                            "t px py pz qx qy qz qw vx vy vz wx wy wz ax ay az bax bay baz bgx bgy bgz"});
  ImuSimulator sim(trajectory, s.options.rig.imu, s.options.seed);
  ImuMeasurement m;
  while (sim.next(m)) {
    if (m.truth.t_ns < s.start_ns) continue;  // the biases still walk from the trajectory's start
    if (m.truth.t_ns > s.end_ns) break;
    imu.append(m.sample);
    io::ImuTruthState x;
    x.t_ns = m.truth.t_ns;
    x.T_W_B = m.truth.T_W_B;
    x.v_W = m.truth.v_W;
    x.omega_B = m.truth.omega_B;
    x.a_W = m.truth.a_W;
    x.accel_bias = m.accel_bias;
    x.gyro_bias = m.gyro_bias;
    state.append(x);
    ++stats->imu_samples;
  }
  imu.close();
  state.close();
  stats->files.push_back(path(folder, "imu.txt"));
  stats->files.push_back(path(folder, "truth/imu_state.txt"));
}

/// range.txt and truth/range.txt.
void writeRange(const Scenario& s, const scenes::Scene& scene, const SensorRig& rig, const std::string& folder,
                SimulationStats* stats) {
  RangeFinder finder(*rig.range_finder, RangeFinder::sceneRayCast(scene), s.options.seed);
  io::RangeWriter reading(path(folder, "range.txt"));
  io::RangeWriter truth(path(folder, "truth/range.txt"),
                        {"true distance along the beam to the first surface (valid = 0: none), no noise, "
                         "no range limits"});
  for (const TimeNs t : clockStamps(s.start_ns, s.end_ns, s.options.rig.range_finder.rate_hz)) {
    const RangeMeasurement m = finder.measure(t, s.trajectory->evaluate(t).T_W_B);
    reading.append(m.reading);
    const bool hit = std::isfinite(m.true_range_m);
    truth.append(io::RangeSample{t, hit ? m.true_range_m : 0.0, hit});
    ++stats->range_samples;
  }
  reading.close();
  truth.close();
  stats->files.push_back(path(folder, "range.txt"));
  stats->files.push_back(path(folder, "truth/range.txt"));
}

/// truth/track_points.txt, truth/tracks.txt, truth/tracks_occluded.txt.
void writeTracks(const Scenario& s, const scenes::Scene& scene, const RenderLoopResult& first,
                 const std::string& folder, SimulationStats* stats) {
  const Camera camera = s.eventCamera();
  const Pose T_B_E = s.T_B_E();
  const auto points = pickTrackPoints(camera, first.first_T_W_E, first.first_depth, s.options.output.truth_tracks,
                                      s.options.output.truth_track_border_px);
  io::writeTrackPoints(path(folder, "truth/track_points.txt"), points,
                       {"world points p_W (m) of the ground-truth tracks, picked on a pixel grid at the start",
                        "id px py pz"});
  io::TracksWriter visible(path(folder, "truth/tracks.txt"),
                           {"ground-truth feature tracks: exact projection of truth/track_points.txt through the "
                            "event camera at the groundtruth.txt poses, visible samples only",
                            "id t x y"});
  io::TracksWriter occluded(path(folder, "truth/tracks_occluded.txt"),
                            {"samples of truth/track_points.txt inside the image but hidden behind a surface",
                             "id t x y"});
  const auto cast = RangeFinder::sceneRayCast(scene);
  for (const TimeNs t : clockStamps(s.start_ns, s.end_ns, s.options.output.groundtruth_rate_hz)) {
    const Pose T_W_E = s.trajectory->evaluate(t).T_W_B * T_B_E;
    for (const auto& p : points) {
      const TrackObservation o = observeTrackPoint(camera, T_W_E, p.p_W, cast);
      if (!o.projects) continue;
      if (o.occluded) {
        occluded.append({p.id, t, o.uv});
      } else {
        visible.append({p.id, t, o.uv});
        ++stats->track_samples;
      }
    }
  }
  visible.close();
  occluded.close();
  stats->truth_tracks = points.size();
  for (const char* f : {"truth/track_points.txt", "truth/tracks.txt", "truth/tracks_occluded.txt"})
    stats->files.push_back(path(folder, f));
}

/// Removes optional outputs of an earlier run that this run does not write.
void removeStale(const Scenario& s, const std::string& folder) {
  const auto& o = s.options;
  std::error_code ec;
  if (!o.output.write_events_txt) fs::remove(path(folder, "events.txt"), ec);
  if (!o.rig.range_finder.enabled) {
    fs::remove(path(folder, "range.txt"), ec);
    fs::remove(path(folder, "truth/range.txt"), ec);
  }
  if (!o.rig.frame_camera.enabled) fs::remove(path(folder, "images.txt"), ec);
  if (!o.rig.frame_camera.enabled || !o.output.depth_at_frames) fs::remove(path(folder, "truth/depth.txt"), ec);
  // Frames and depth maps are numbered: a longer earlier run would leave extra ones.
  fs::remove_all(path(folder, "images"), ec);
  fs::remove_all(path(folder, "truth/depth"), ec);
}

}  // namespace

std::string SimulationStats::toYaml() const {
  std::ostringstream s;
  s.precision(6);
  const double event_stage_rate = event_s > 0.0 ? static_cast<double>(pixel_updates) / event_s : 0.0;
  const double equivalents =
      tile_count > 0 ? static_cast<double>(tiles_rendered) / static_cast<double>(tile_count) : 0.0;
  s << "# evio simulate: what the run did and how long it took (wall clock; varies between runs)\n"
    << "simulated_s: " << simulated_s << "\n"
    << "wall_s: " << wall_s << "\n"
    << "simulated_s_per_wall_s: " << realTimeFactor() << "\n"
    << "cpu_s: " << cpu_s << "   # process CPU time, all threads (robust to other load on the machine)\n"
    << "simulated_s_per_cpu_s: " << (cpu_s > 0 ? simulated_s / cpu_s : 0.0) << "\n"
    << "resolution: [" << width << ", " << height << "]\n"
    << "schedule: " << schedule << "\n"
    << "renders: " << renders << "   # whole-frame event-camera renders\n"
    << "tile_steps: " << tile_steps << "   # steps that re-rendered only the tiles due\n"
    << "tiles_rendered: " << tiles_rendered << "   # event-camera tiles traced, whole renders included\n"
    << "tile_count: " << tile_count << "   # tiles per image\n"
    << "render_equivalents: " << equivalents << "   # tiles_rendered / tile_count\n"
    << "render_equivalents_per_simulated_s: " << (simulated_s > 0 ? equivalents / simulated_s : 0.0) << "\n"
    << "renders_per_simulated_s: " << (simulated_s > 0 ? static_cast<double>(renders) / simulated_s : 0.0) << "\n"
    << "renders_per_wall_s: " << (render_s > 0 ? equivalents / render_s : 0.0)
    << "   # render equivalents per second of render time\n"
    << "frame_renders: " << frame_renders << "\n"
    << "pixel_updates: " << pixel_updates << "\n"
    << "event_stage_pixel_updates_per_s: " << event_stage_rate << "\n"
    << "event_stage_pixel_updates_per_cpu_s: "
    << (event_cpu_s > 0 ? static_cast<double>(pixel_updates) / event_cpu_s : 0.0) << "\n"
    << "render_cpu_s_per_render: " << (equivalents > 0 ? render_cpu_s / equivalents : 0.0)
    << "   # per render equivalent\n"
    << "events: " << events << "\n"
    << "events_per_simulated_s: " << (simulated_s > 0 ? static_cast<double>(events) / simulated_s : 0.0) << "\n"
    << "events_per_wall_s: " << (wall_s > 0 ? static_cast<double>(events) / wall_s : 0.0) << "\n"
    << "frames: " << frames << "\n"
    << "depth_maps: " << depth_maps << "\n"
    << "imu_samples: " << imu_samples << "\n"
    << "groundtruth_poses: " << groundtruth_poses << "\n"
    << "range_samples: " << range_samples << "\n"
    << "truth_tracks: " << truth_tracks << "\n"
    << "track_samples: " << track_samples << "\n"
    << "stage_wall_s:\n"
    << "  scene_build: " << scene_build_s << "\n"
    << "  render: " << render_s << "\n"
    << "  frame_render: " << frame_render_s << "\n"
    << "  event_camera: " << event_s << "\n"
    << "  schedule: " << schedule_s << "\n"
    << "  frame_camera: " << frame_s << "\n"
    << "  write: " << write_s << "\n"
    << "  truth: " << truth_s << "\n";
  return s.str();
}

SimulationStats simulateSequence(const Scenario& scenario, const std::string& folder,
                                 const ProgressCallback& progress) {
  const Stopwatch total;
  const double cpu_start_s = Stopwatch::processCpuSeconds();
  SimulationStats stats;
  const auto& o = scenario.options;
  stats.simulated_s = nsToSeconds(scenario.end_ns - scenario.start_ns);
  const SensorRig rig = scenario.sensorRig();
  const Camera event_camera = scenario.eventCamera();
  stats.width = event_camera.width();
  stats.height = event_camera.height();

  std::error_code ec;
  fs::create_directories(fs::path(folder) / "truth", ec);
  if (ec) throw Error(folder + ": cannot create the output folder: " + ec.message());
  removeStale(scenario, folder);

  // The static files.
  io::writeFileAtomic(path(folder, "scenario.yaml"), scenario.resolvedYaml());
  io::writeSensorsYaml(path(folder, "sensors.yaml"), rig);
  io::writeCalibTxt(path(folder, "calib.txt"), io::calibTxtFromCamera(event_camera));
  for (const char* f : {"scenario.yaml", "sensors.yaml", "calib.txt"}) stats.files.push_back(path(folder, f));

  Stopwatch watch;
  writeMotion(scenario, folder, &stats);
  stats.truth_s += watch.seconds();

  watch.restart();
  scenes::SceneBuildOptions build;
  build.threads = o.threads;
  const scenes::Scene scene(scenario.scene, build);
  stats.scene_build_s = watch.seconds();

  if (rig.range_finder) {
    watch.restart();
    writeRange(scenario, scene, rig, folder, &stats);
    stats.truth_s += watch.seconds();
  }

  SequenceWriterOptions wo;
  wo.width = event_camera.width();
  wo.height = event_camera.height();
  wo.t_offset_ns = scenario.start_ns;
  wo.events_txt = o.output.write_events_txt;
  wo.events_h5_compression = o.output.events_h5_compression;
  wo.frames = o.rig.frame_camera.enabled;
  wo.depth = o.rig.frame_camera.enabled && o.output.depth_at_frames;
  AsyncSequenceWriter writer(folder, wo);  // writes on a thread of its own while the loop renders
  const RenderLoopResult first = runRenderLoop(scenario, scene, writer, progress, &stats);
  watch.restart();
  for (auto& f : writer.close()) stats.files.push_back(f);
  stats.write_s += watch.seconds();
  stats.events = writer.eventCount();
  stats.frames = writer.frameCount();
  stats.depth_maps = writer.depthCount();

  watch.restart();
  writeTracks(scenario, scene, first, folder, &stats);
  stats.truth_s += watch.seconds();

  stats.wall_s = total.seconds();
  stats.cpu_s = Stopwatch::processCpuSeconds() - cpu_start_s;
  const std::string stats_path = path(folder, "simulation_stats.yaml");
  io::writeFileAtomic(stats_path, stats.toYaml());
  stats.files.push_back(stats_path);
  return stats;
}

}  // namespace evio::simulator

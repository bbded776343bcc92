#pragma once
/// @file scenario.h
/// A scenario: what `evio simulate <scenario.yaml> -o <folder>` turns into a
/// sequence folder — a scene, a trajectory, a sensor rig, a time window and
/// a seed (experiments/scenarios/*.yaml are examples).
///
///   description: "one line"
///   seed: 1                     # every random stream of the run (the trajectory's seed too)
///   start_s: 0                  # the sequence covers trajectory time [start_s, start_s + duration_s]
///   duration_s: 10
///   threads: 0                  # 0 = all cores; never changes the output
///   scene: <path> | {preset: <path>, <top-level keys replaced>} | {<inline scene>}
///   trajectory: <path> | {preset: <path>, <keys replaced>} | {<inline trajectory>}
///   rig:
///     event_camera: {preset: <simulator/presets/*.yaml>, <EventCameraRigOptions keys>}
///     frame_camera: {preset: <simulator/presets/aps_*.yaml>, sensor: {...}, ...}  # FrameCameraRigOptions
///     imu: {...}                # ImuSimulator::Options, Kalibr names
///     range_finder: {...}       # RangeFinderRigOptions
///   sampling: {...}             # RenderScheduleOptions
///   output: {...}               # SequenceOutputOptions
///
/// Paths are resolved relative to the scenario file's folder first, then to
/// `search_root` (the repository, so `scenes/presets/mars_yard.yaml` works
/// from anywhere). A `{preset: ...}` map loads the preset and replaces the
/// keys given beside `preset` (event_camera: merged key by key, nested maps
/// included; lists are replaced whole; frame_camera: the preset fills
/// `sensor`, under the keys of `sensor:`). Unknown keys are an error naming the
/// file and line; `--set` overrides (`rig.imu.update_rate_hz=200`,
/// `trajectory.center_m=[0,0,2]`, `duration_s=2`) apply before resolving.
///
/// Frames: B the body (IMU) of the trajectory, E the event camera (T_B_E),
/// F a separate frame camera (T_B_F); all rigid transforms are 4×4 row-major
/// lists of 16 numbers.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "evio/core/eigen_types.h"
#include "evio/core/io/config.h"
#include "evio/core/io/events_h5.h"
#include "evio/core/options.h"
#include "evio/core/sensor_rig.h"
#include "evio/core/time.h"
#include "evio/scenes/scene_description.h"
#include "evio/simulator/event_sensor_preset.h"
#include "evio/simulator/frame_camera.h"
#include "evio/simulator/imu_simulator.h"
#include "evio/trajectories/continuous_trajectory.h"

namespace evio::simulator {

/// The event camera: a sensor preset's fields (name, width, height,
/// intrinsics, pixel_pitch_um, event_camera) plus the lens model and mounting.
struct EventCameraRigOptions {
  std::string preset;                 ///< sensor preset file whose values are the defaults; "" = none
  EventSensorPreset sensor;           ///< listed flat beside `preset`
  std::string model = "pinhole";      ///< pinhole or radtan (calib.txt holds no other)
  std::vector<double> distortion;     ///< radtan: k1 k2 p1 p2 k3; pinhole: empty
  Mat4 T_B_E = Mat4::Identity();      ///< event camera E into body B, row-major 4×4

  template <class V>
  void fields(V& v) {
    v("preset", preset, "event sensor preset file (defaults of the other keys)");
    sensor.fields(v);
    v("model", model, "lens model: pinhole or radtan");
    v("distortion", distortion, "radtan k1 k2 p1 p2 k3; empty for pinhole");
    v("T_B_E", T_B_E, "event camera into body (IMU) frame, 4x4 row-major");
  }
  void validate() const;
};

/// The frame camera: the event camera's own pixels (DAVIS APS frames,
/// `co_located`) or a separate camera with its own lens and mounting. Its
/// sensor's defaults may come from a preset file (simulator/presets/aps_*.yaml:
/// the FrameCamera::Options keys, each with its source), over which the keys
/// of `sensor:` are merged.
struct FrameCameraRigOptions {
  std::string preset;                 ///< frame sensor preset file (defaults of `sensor`); "" = none
  bool enabled = true;                ///< write images.txt and images/
  bool co_located = true;             ///< frames from the event pixels (same camera, pose and renders)
  double rate_hz = 20.0;              ///< frame rate: exposure k starts at start + k / rate_hz
  int exposure_samples = 3;           ///< N renders evenly over the frame's span, both ends (motion blur, rolling shutter)
  /// Meter the first exposure on a render of the first view: the exposure
  /// whose noise-free mean DN/255 is the auto-exposure target,
  /// t = (target^γ · full_well) / (K · mean radiance), within the exposure
  /// limits (frame_camera.h); otherwise start at sensor.exposure_s. Only
  /// with auto-exposure on (either method: it stands in for an operator
  /// setting a first exposure for the scene); a fixed exposure stays fixed.
  bool meter_first_exposure = true;
  std::string name = "frames";        ///< camera name in sensors.yaml
  // A separate camera only (co_located = false):
  std::string model = "pinhole";      ///< pinhole, radtan or equidistant
  int width = 752;                    ///< px (mvBlueFOX-MLC200w: 752 × 480)
  int height = 480;                   ///< px
  Vec4 intrinsics = Vec4(470.0, 470.0, 375.5, 239.5);  ///< fx fy cx cy, px
  std::vector<double> distortion;     ///< as Camera::create
  Mat4 T_B_F = Mat4::Identity();      ///< frame camera F into body B, row-major 4×4
  /// Exposure, auto-exposure, readout, noise. The auto-exposure never goes
  /// past 1 / rate_hz − sensor.readout_s.
  FrameCamera::Options sensor;

  template <class V>
  void fields(V& v) {
    v("preset", preset, "frame sensor preset file (defaults of sensor.*)");
    v("enabled", enabled, "write frames");
    v("co_located", co_located, "frames from the event camera's pixels (DAVIS APS)");
    v("rate_hz", rate_hz, "frame rate, Hz");
    v("exposure_samples", exposure_samples, "renders over each exposure (motion blur)");
    v("meter_first_exposure", meter_first_exposure, "set the first exposure from a render of the first view");
    v("name", name, "camera name in sensors.yaml");
    v("model", model, "separate camera: lens model");
    v("width", width, "separate camera: width, px");
    v("height", height, "separate camera: height, px");
    v("intrinsics", intrinsics, "separate camera: fx fy cx cy, px");
    v("distortion", distortion, "separate camera: distortion coefficients");
    v("T_B_F", T_B_F, "separate camera into body (IMU) frame, 4x4 row-major");
    v("sensor", sensor, "sensor: exposure, auto-exposure, noise");
  }
  void validate() const;
};

/// An optional single-beam laser range finder (range_finder.h).
struct RangeFinderRigOptions {
  bool enabled = false;
  double rate_hz = 20.0;              ///< measurements per second
  Mat4 T_B_L = Mat4::Identity();      ///< range finder L (beam along +z) into body B
  double min_range_m = 0.1;
  double max_range_m = 100.0;
  double noise_sigma_m = 0.02;

  template <class V>
  void fields(V& v) {
    v("enabled", enabled, "write range.txt");
    v("rate_hz", rate_hz, "measurement rate, Hz");
    v("T_B_L", T_B_L, "range finder (beam +z) into body frame, 4x4 row-major");
    v("min_range_m", min_range_m, "shortest range, m");
    v("max_range_m", max_range_m, "longest range, m");
    v("noise_sigma_m", noise_sigma_m, "range noise sigma, m");
  }
  void validate() const;
};

struct RigOptions {
  EventCameraRigOptions event_camera;
  FrameCameraRigOptions frame_camera;
  /// The IMU. gravity_mps2 defaults to the trajectory's gravity when not given.
  ImuSimulator::Options imu;
  RangeFinderRigOptions range_finder;

  template <class V>
  void fields(V& v) {
    v("event_camera", event_camera, "event camera");
    v("frame_camera", frame_camera, "frame camera");
    v("imu", imu, "IMU (Kalibr names)");
    v("range_finder", range_finder, "laser range finder");
  }
  void validate() const;
};

/// When the event camera is rendered (whole frames; see sequence_simulator.h).
/// After a render at t the next is due after
///   Δt = clamp(λ C / Ṙ_q, 1 / max_rate_hz, 1 / min_rate_hz),
/// Ṙ_q the q-quantile over pixels of the predicted |dL/dt| (AdaptiveSampler:
/// rate_bound as there), q = fastest_pixel_quantile (1: the fastest pixel, ESIM).
struct RenderScheduleOptions {
  /// "whole_frame": every step re-renders the whole image, at the interval
  /// predicted from the fastest-pixel quantile; "tiles": every tile of
  /// tile_px has its own next-sample time from its fastest pixel
  /// (tile_schedule.h) and a step re-renders only the tiles due.
  std::string schedule = "whole_frame";
  double lambda = 0.5;                ///< λ: fraction of the threshold L may change between renders
  double min_rate_hz = 100.0;         ///< renders at least this often, Hz (per tile with "tiles")
  double max_rate_hz = 1000.0;        ///< at most this often (cost bound), Hz (per tile with "tiles")
  bool rate_bound = true;             ///< predict with max neighbour slope · |flow| (else |∇L · flow|)
  double fastest_pixel_quantile = 1.0;///< q ∈ (0, 1]: 1 = the fastest pixel ("whole_frame" only)
  /// Render tile edge, px: the renderer's work unit and, with "tiles", the
  /// schedule's tiles. 0 = by schedule: 16 px for "whole_frame" (whose
  /// events depend slightly on it: a few rays' bits change with the ray
  /// streams, docs/simulation.md) and 8 px for "tiles" (fewer rays than 16 px
  /// where the rates differ within a tile; README "Simulation (issue 5)").
  /// The loader replaces 0 by the tile in use, so a resolved scenario.yaml
  /// states it (and keeps it if re-run with the other schedule).
  int tile_px = 0;
  double tile_quantum_s = 0.0;        ///< "tiles": due times on a grid of this period, s; 0 = 1 / max_rate_hz
  int supersampling = 1;              ///< n × n radiance rays per pixel

  template <class V>
  void fields(V& v) {
    v("schedule", schedule, "whole_frame (whole renders) or tiles (per-tile adaptive renders)");
    v("lambda", lambda, "fraction of the contrast threshold between renders");
    v("min_rate_hz", min_rate_hz, "minimum render rate, Hz");
    v("max_rate_hz", max_rate_hz, "maximum render rate, Hz");
    v("rate_bound", rate_bound, "predict with max neighbour slope * |flow| (else |grad L . flow|)");
    v("fastest_pixel_quantile", fastest_pixel_quantile, "pixel quantile of the predicted rate (1 = fastest)");
    v("tile_px", tile_px, "render tile edge, px (the schedule's tiles with schedule: tiles); 0 = 16 whole_frame, 8 tiles");
    v("tile_quantum_s", tile_quantum_s, "tiles: due times on a grid of this period, s (0 = 1 / max_rate_hz)");
    v("supersampling", supersampling, "n x n radiance rays per pixel");
  }
  void validate() const;
  bool tiles() const { return schedule == "tiles"; }
  /// The tile edge in use, px: tile_px, or the schedule's default when 0.
  int tilePx() const { return tile_px > 0 ? tile_px : (tiles() ? 8 : 16); }
  /// The grid period of the "tiles" schedule, ns.
  TimeNs tileQuantumNs() const;
};

struct SequenceOutputOptions {
  bool write_events_txt = true;       ///< events.txt beside events.h5 (off for large runs)
  int events_h5_compression = 0;      ///< gzip level of events.h5 (0: none, fastest)
  double groundtruth_rate_hz = 200.0; ///< groundtruth.txt and truth/tracks.txt rate, Hz
  bool depth_at_frames = true;        ///< truth/depth/*.exr: event-camera depth at each frame stamp
  bool flow_at_frames = false;        ///< add the motion field (channels U, V, px/s) to those files (3× the size)
  int truth_tracks = 100;             ///< ground-truth feature tracks (points visible at the start)
  double truth_track_border_px = 8.0; ///< track points are picked this far inside the image, px

  template <class V>
  void fields(V& v) {
    v("write_events_txt", write_events_txt, "write events.txt too");
    v("events_h5_compression", events_h5_compression, "gzip level of events.h5, 0 = none");
    v("groundtruth_rate_hz", groundtruth_rate_hz, "groundtruth.txt and truth/tracks.txt rate, Hz");
    v("depth_at_frames", depth_at_frames, "event-camera depth EXR at frame stamps");
    v("flow_at_frames", flow_at_frames, "add the motion field (U, V, px/s) to the depth EXR files");
    v("truth_tracks", truth_tracks, "number of ground-truth feature tracks");
    v("truth_track_border_px", truth_track_border_px, "margin of the track start points, px");
  }
  void validate() const;
};

/// Every field of a scenario except scene and trajectory (those are resolved
/// by loadScenario into the Scenario beside it).
struct ScenarioOptions {
  std::string description;
  std::uint64_t seed = 1;
  double start_s = 0.0;
  double duration_s = 10.0;
  int threads = 0;
  RigOptions rig;
  RenderScheduleOptions sampling;
  SequenceOutputOptions output;

  template <class V>
  void fields(V& v) {
    v("description", description, "one line for humans");
    v("seed", seed, "seed of every random stream");
    v("start_s", start_s, "start of the sequence in trajectory time, s");
    v("duration_s", duration_s, "length of the sequence, s");
    v("threads", threads, "threads, 0 = all cores (the output does not depend on it)");
    v("rig", rig, "sensor rig");
    v("sampling", sampling, "render schedule");
    v("output", output, "what to write");
  }
  void validate() const;
};

/// A loaded scenario, everything resolved.
struct Scenario {
  ScenarioOptions options;
  std::string file;                             ///< the scenario file ("<string>" for text)
  scenes::SceneDescription scene;               ///< the scene
  std::shared_ptr<const ContinuousTrajectory> trajectory;  ///< the motion of B
  TimeNs start_ns = 0;                          ///< first instant of the sequence
  TimeNs end_ns = 0;                            ///< last instant

  /// The rig as sensors.yaml holds it: the event camera first ("cam0"), then
  /// the frame camera (co-located: the same camera and T_B_C), IMU, gravity,
  /// range finder, time offset.
  SensorRig sensorRig() const;
  /// The event camera model (validated).
  Camera eventCamera() const;
  Pose T_B_E() const;
  /// The frame camera's model and T_B_F (the event camera's when co-located).
  Camera frameCamera() const;
  Pose T_B_F() const;

  /// The resolved scenario as YAML (seed, version, scene and trajectory
  /// inline, every field; `threads` left out since it never changes the
  /// output). Loading it again gives the same sequence.
  std::string resolvedYaml() const;
};

/// Loads a scenario file; `search_root` is the second folder relative paths
/// are tried in (e.g. the repository). Throws Error with file:line/field.
Scenario loadScenario(const std::string& path, const std::vector<std::string>& overrides = {},
                      const std::string& search_root = "");

/// The same from YAML text; relative paths resolve against `base_dir`, then `search_root`.
Scenario loadScenarioString(const std::string& text, const std::string& name, const std::string& base_dir,
                            const std::vector<std::string>& overrides = {}, const std::string& search_root = "");

/// A rigid transform from a row-major 4×4 option; throws Error naming
/// `field` unless the rotation block is orthonormal (1e-6) with det +1 and
/// the last row is 0 0 0 1.
Pose rigidFromMatrix(const Mat4& T, const std::string& field);

}  // namespace evio::simulator

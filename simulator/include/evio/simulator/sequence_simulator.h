#pragma once
/// @file sequence_simulator.h
/// `evio simulate`: a scenario (scenario.h) in, a complete sequence folder
/// (docs/architecture.md#the-sequence-folder) out, with exact ground truth:
///
///   scenario.yaml         the resolved scenario (seed, version, every field)
///   sensors.yaml          the rig: cam0 = event camera, then the frame camera
///                         (parameter co_located_with_cam0 = 1 for DAVIS-style frames)
///   calib.txt             event camera intrinsics (pinhole or radtan)
///   groundtruth.txt       T_W_E: the event camera in W (TUM), at output.groundtruth_rate_hz
///   imu.txt               the IMU (B frame, Kalibr noise model; imu_simulator.h)
///   events.h5, events.txt, images.txt, images/    (sequence_writer.h)
///   range.txt             when the rig has a range finder
///   truth/imu_state.txt   true IMU state and biases at every IMU sample
///   truth/event_labels.bin, truth/depth.txt, truth/depth/   (sequence_writer.h; depth,
///                         and the motion field with output.flow_at_frames)
///   truth/track_points.txt, truth/tracks.txt, truth/tracks_occluded.txt
///                         ground-truth feature tracks (truth_tracks.h) at the
///                         groundtruth.txt stamps: tracks.txt the visible samples,
///                         tracks_occluded.txt those inside the image but hidden
///   truth/range.txt       the true range (valid = a surface was hit) at each range.txt stamp
///   simulation_stats.yaml counts and wall-clock times (the only file that
///                         differs between two runs)
///
/// Render scheduling (scenario.h, RenderScheduleOptions::schedule).
/// "whole_frame": the event camera is sampled by whole frames at adaptive
/// steps: after a render at t the next one is due after
/// Δt = clamp(λ C / Ṙ_q, 1 / max_rate_hz, 1 / min_rate_hz), Ṙ_q from the
/// rendered radiance and the analytic motion field. "tiles": each tile has
/// its own next-sample time (tile_schedule.h) and a step re-renders only the
/// tiles due (Renderer::renderTiles), feeding their pixels to the event
/// camera (EventCamera::updateRects). Whole renders are also placed at every frame sub-sample (a
/// co-located frame camera shares the event camera's renders and feeds them
/// to the event camera too), at every frame stamp (depth truth) and at the
/// end of the window. A separate frame camera renders its own sub-samples.
/// The IMU, ground truth, range finder and tracks run on their own clocks
/// straight from the trajectory and the scene.
///
/// Determinism: the renderer, the event camera and the frame camera give
/// results independent of the thread count, everything else runs in a fixed
/// order (the event stage of a step, overlapped with the next render, one
/// stage at a time; each file written by one thread in order), so the same
/// scenario and seed give byte-identical files (simulation_stats.yaml aside)
/// whatever `threads` is.

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "evio/simulator/scenario.h"

namespace evio::simulator {

/// Reported after every render.
struct SimulationProgress {
  double simulated_s = 0.0;  ///< sequence time done, s
  double total_s = 0.0;      ///< sequence length, s
  std::uint64_t events = 0;
  std::uint64_t renders = 0;         ///< whole-frame renders of the event camera
  std::uint64_t tiles_rendered = 0;  ///< event-camera tiles traced, whole renders included
};
using ProgressCallback = std::function<void(const SimulationProgress&)>;

/// What a run did and how long each stage took (wall clock, s).
struct SimulationStats {
  double simulated_s = 0.0;
  double wall_s = 0.0;               ///< everything, scene build included
  double cpu_s = 0.0;                ///< process CPU time over the run (all threads), s
  double scene_build_s = 0.0;
  double render_s = 0.0;             ///< event-camera renders (flow included)
  double frame_render_s = 0.0;       ///< separate frame-camera renders
  double event_s = 0.0;              ///< event stage (EventCamera update/emit); overlaps the renders with 2+ threads
  double schedule_s = 0.0;           ///< adaptive step prediction
  double frame_s = 0.0;              ///< FrameCamera::capture
  double write_s = 0.0;              ///< handing events, frames, depth to the writer thread, and closing the files
  double render_cpu_s = 0.0;         ///< process CPU time during the event-camera renders (an overlapping event stage included)
  double event_cpu_s = 0.0;          ///< CPU time of the thread that ran each event stage
  double truth_s = 0.0;              ///< ground truth, IMU, range, tracks passes
  int width = 0, height = 0;         ///< event sensor, px
  std::string schedule;              ///< sampling.schedule: whole_frame or tiles
  std::uint64_t renders = 0;         ///< whole-frame event-camera renders
  std::uint64_t tile_steps = 0;      ///< steps that re-rendered only the tiles due ("tiles")
  std::uint64_t tiles_rendered = 0;  ///< event-camera tiles traced (whole renders included)
  std::uint64_t tile_count = 0;      ///< tiles per event-camera image
  std::uint64_t frame_renders = 0;   ///< separate frame-camera renders
  std::uint64_t pixel_updates = 0;   ///< event-camera pixel samples
  std::uint64_t events = 0;
  std::uint64_t frames = 0;
  std::uint64_t depth_maps = 0;
  std::uint64_t imu_samples = 0;
  std::uint64_t groundtruth_poses = 0;
  std::uint64_t range_samples = 0;
  std::uint64_t truth_tracks = 0;
  std::uint64_t track_samples = 0;   ///< visible samples in tracks.txt
  std::vector<std::string> files;    ///< paths written

  /// The figures of the README table: simulated s per wall s, events per
  /// simulated s, renders per wall s, pixel updates per s of event stage.
  double realTimeFactor() const { return wall_s > 0.0 ? simulated_s / wall_s : 0.0; }
  /// As YAML (simulation_stats.yaml).
  std::string toYaml() const;
};

/// Runs the scenario into `folder` (created when missing; files of an earlier
/// run are replaced, optional ones this run does not write are removed).
/// Throws Error for bad input or a failed write.
SimulationStats simulateSequence(const Scenario& scenario, const std::string& folder,
                                 const ProgressCallback& progress = {});

}  // namespace evio::simulator

#pragma once
/// @file pipeline.h
/// The estimator pipelines (Mahlknecht et al. 2022; docs/architecture.md#the-estimator-stages): EKLT-VIO
/// (EKLT frontend + synchroniser + EKF backend), KLT-VIO (KLT frontend +
/// backend updated per frame) and `tracks` (backend on feature tracks read
/// from a file), run over a sequence folder (docs/architecture.md#the-sequence-folder, recorded or
/// simulated) and written as an estimate folder (estimate_writer.h).
///
/// Streaming (memory flat in the sequence length): events in chunks, IMU one
/// sample at a time and frames loaded when their turn comes, all merged in
/// time order on the camera clock (sequence_reader.h); the frontend, the
/// synchroniser and the backend are fed as the data arrive, exactly as they
/// would be online.
///
/// Calibration: sensors.yaml, else calib.txt + options.calibration
/// (sequence_rig.h). The trajectory is the event camera's pose
/// T_W_E = T_W_B · T_B_E (the frame of groundtruth.txt) whatever camera the
/// tracker used.
///
/// Initialisation (options.init, pipeline_options.h): from groundtruth.txt at
/// the first IMU time (the paper's protocol), or static.
///
/// Bad input and degraded modes (each an evio::Error with one clear message,
/// or a status in status.yaml — never a crash):
///  - events out of order, malformed files: evio::Error from the readers,
///    naming file and line (or HDF5 index);
///  - no frames (images.txt missing or empty): eklt-vio and haste-vio with
///    frontend.image_source frames and klt-vio throw an evio::Error saying so
///    (eklt-vio and haste-vio run without frames with frontend.image_source
///    reconstructed);
///  - calibration that does not match the data (frame size or the sensor size
///    stored in events.h5 differing from sensors.yaml / calib.txt, events
///    outside the sensor): evio::Error naming both sizes;
///  - IMU gaps: gaps up to backend.imu_max_gap_s are normal, longer ones are
///    bridged by interpolation and counted (summary.yaml imu_gaps); a gap
///    above backend.imu_fail_gap_s after initialisation ends the run with
///    status `failed` ("IMU gap of … s"), the trajectory up to the gap kept.
///    The same holds when imu.txt ends while events or frames continue;
///  - divergence: status `diverged` with its time and cause (backend_status.h);
///  - static initialisation that never finds a still window: status `failed`.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "evio/core/io/status_yaml.h"
#include "evio/estimator/backend/backend_status.h"
#include "evio/estimator/backend/gyro_bias_from_tracks.h"
#include "evio/estimator/pipeline/pipeline_options.h"

namespace evio::estimator {

struct PipelineProgress {
  double fraction = 0.0;      ///< share of the data read, 0..1
  TimeNs t_ns = 0;            ///< data time reached (camera clock)
  std::uint64_t events = 0;   ///< events read so far
  bool initialized = false;
};
using PipelineProgressCallback = std::function<void(const PipelineProgress&)>;

/// Wall-clock seconds per stage (steady clock), summed over the run.
struct PipelineStageTimes {
  double setup_s = 0.0;     ///< opening files, calibration, initial ground truth
  double read_s = 0.0;      ///< reading events, IMU and frames
  double frontend_s = 0.0;  ///< pre-filters, reconstruction, tracking, synchroniser
  double backend_s = 0.0;   ///< EKF propagation and updates
  double output_s = 0.0;    ///< writing the estimate files
  double total_s = 0.0;     ///< the whole run
  double cpu_s = 0.0;       ///< CPU time of the process over the whole run (std::clock, all threads)

  template <class V>
  void fields(V& v) {
    v("setup_s", setup_s, "opening files, calibration, initial ground truth, s");
    v("read_s", read_s, "reading events, IMU and frames, s");
    v("frontend_s", frontend_s, "pre-filters, reconstruction, tracking, synchroniser, s");
    v("backend_s", backend_s, "EKF propagation and updates, s");
    v("output_s", output_s, "writing the estimate files, s");
    v("total_s", total_s, "the whole run, s");
    v("cpu_s", cpu_s, "CPU time of the process over the whole run, s");
  }
};

/// CPU seconds per stage (the CPU clock of the thread that ran the stage;
/// tracking includes the tracker's worker threads), summed over the run.
/// Each thread's CPU clock is read once per 20 ms window and shared among
/// the stages it ran in the window by their busy wall time (the tracker's
/// wait for its workers left out; stage_cpu_split.h: exact per stage on an
/// idle core), never per event. The `eklt_*` entries split EKLT's tracking time as the tracker
/// itself measures it (wall seconds summed over its threads; 0 for the other
/// trackers).
struct PipelineStageCpu {
  double read_s = 0.0;       ///< reading events, IMU and frames (decoding PNG included)
  double prefilter_s = 0.0;  ///< event pre-filters
  double tracking_s = 0.0;   ///< the frontend: reconstruction and tracker (all its threads)
  double tracking_workers_s = 0.0;        ///< of tracking_s, the tracker's worker threads
  /// tracking_s with each chunk's parallel parts counted as their slowest
  /// part: the tracking's wall time on idle cores (thread wake-ups not
  /// counted); equals tracking_s on one thread.
  double tracking_critical_path_s = 0.0;
  double sync_s = 0.0;       ///< synchroniser (tracks_ method: reading the tracks)
  double backend_s = 0.0;    ///< EKF propagation and updates
  double output_s = 0.0;     ///< health monitor, writing the estimate files, timing and progress
  double eklt_optimisation_s = 0.0;  ///< EKLT: the per-batch optimisations
  double eklt_events_s = 0.0;        ///< EKLT: event lookup and splatting (events minus optimisation)
  double eklt_frames_s = 0.0;        ///< EKLT: frames (log image, gradients, templates, detection, bootstrap)

  template <class V>
  void fields(V& v) {
    v("read_s", read_s, "reading events, IMU and frames, CPU s");
    v("prefilter_s", prefilter_s, "event pre-filters, CPU s");
    v("tracking_s", tracking_s, "frontend (reconstruction and tracker), CPU s");
    v("tracking_workers_s", tracking_workers_s, "of tracking_s, the tracker's worker threads, CPU s");
    v("tracking_critical_path_s", tracking_critical_path_s,
      "tracking with each chunk's parallel parts counted as the slowest part, CPU s");
    v("sync_s", sync_s, "synchroniser, CPU s");
    v("backend_s", backend_s, "EKF propagation and updates, CPU s");
    v("output_s", output_s, "health monitor and estimate files, CPU s");
    v("eklt_optimisation_s", eklt_optimisation_s, "EKLT optimisations, s summed over tracker threads");
    v("eklt_events_s", eklt_events_s, "EKLT event lookup and splatting, s summed over tracker threads");
    v("eklt_frames_s", eklt_frames_s, "EKLT frames: log image, gradients, templates, detection, bootstrap, s");
  }
};

/// EKLT's optimiser work (summary.yaml `eklt`): what the tracking's CPU
/// time is spent on.
struct EkltSolverCounts {
  std::uint64_t events_in_patches = 0;  ///< (event, feature) splats
  std::uint64_t optimisations = 0;      ///< solver runs (reversal solves included)
  std::uint64_t solver_iterations = 0;  ///< cost evaluations with Jacobian, all runs
  std::uint64_t reversal_solves = 0;    ///< second solves from the reversed flow direction
  std::uint64_t batches_dropped = 0;    ///< batches without a plausible solution

  template <class V>
  void fields(V& v) {
    v("events_in_patches", events_in_patches, "(event, feature) splats");
    v("optimisations", optimisations, "solver runs, reversal solves included");
    v("solver_iterations", solver_iterations, "solver iterations over all runs");
    v("reversal_solves", reversal_solves, "second solves from the reversed flow direction");
    v("batches_dropped", batches_dropped, "batches without a plausible solution");
  }
};

/// What went through the chain (summary.yaml `counts`).
struct PipelineCounts {
  std::uint64_t events = 0;            ///< events read
  std::uint64_t events_kept = 0;       ///< after the pre-filters
  std::uint64_t frames = 0;            ///< frames given to the frontend
  std::uint64_t imu_samples = 0;
  std::uint64_t track_points = 0;
  std::uint64_t measurement_sets = 0;  ///< given to the backend
  std::uint64_t poses = 0;             ///< lines of trajectory.txt

  template <class V>
  void fields(V& v) {
    v("events", events, "events read");
    v("events_kept", events_kept, "events after the pre-filters");
    v("frames", frames, "frames given to the frontend");
    v("imu_samples", imu_samples, "IMU samples read");
    v("track_points", track_points, "track points from the frontend");
    v("measurement_sets", measurement_sets, "measurement sets given to the backend");
    v("poses", poses, "lines of trajectory.txt");
  }
};

struct PipelineResult {
  io::EstimateStatus status;
  BackendStats backend;
  PipelineStageTimes times;
  PipelineStageCpu cpu;
  PipelineCounts counts;
  std::string rig_source;          ///< sensors.yaml or calib.txt
  std::string tracker_camera;      ///< camera whose pixels the tracker used
  std::string events_file;         ///< events.h5, events.txt or empty
  TimeNs t_first_ns = 0;           ///< data span read (camera clock)
  TimeNs t_last_ns = 0;
  std::optional<TimeNs> initialization_t_ns;
  /// The tracker's lag estimated from the frames at the end
  /// (frontend.track_lag.estimate; track_lag.h).
  std::optional<TrackLag> track_lag;
  std::optional<EkltSolverCounts> eklt;  ///< EKLT-VIO only
  /// The gyroscope bias estimated from the first tracks (init.gyro_bias_window_s > 0).
  std::optional<GyroBiasEstimate> gyro_bias;
  std::vector<std::string> notes;  ///< degraded modes and choices made (one line each)
};

/// Runs `options.method` over `sequence` and writes the estimate folder
/// `output` (created when missing). Throws evio::Error for bad input (see
/// the file comment); filter divergence and failure are in the result and
/// status.yaml instead. For the run, OpenCV's (process-wide) thread count is
/// set to frontend.threads (0, the calling thread alone, for one) and then
/// restored: runs in one process must not overlap.
PipelineResult runPipeline(const std::string& sequence, const PipelineOptions& options, const std::string& output,
                           const PipelineProgressCallback& progress = {});

/// summary.yaml: the result's counters, stage times and backend statistics.
std::string formatPipelineSummary(const PipelineResult& result, const PipelineOptions& options);

}  // namespace evio::estimator

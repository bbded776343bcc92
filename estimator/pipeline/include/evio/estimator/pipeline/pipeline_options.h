#pragma once
/// @file pipeline_options.h
/// The whole configuration of an estimator run (`evio estimate`): method,
/// frontend, synchroniser, backend, initialisation, calibration fall-backs,
/// the tracks input and the outputs, in one nested Options struct so that
/// every key can be set from a YAML file or `--set a.b=value`
/// (core/io/config.h), e.g. `frontend.eklt.patch_size_px=17`,
/// `backend.max_slam_features=15`, `sync.n_e=3200`.
///
/// Methods (Mahlknecht et al. 2022; docs/architecture.md#the-estimator-stages):
///  - `eklt-vio`: EKLT on events and frames (or frames reconstructed from
///    events, `frontend.image_source: reconstructed`), synchroniser trigger
///    every n_e events, backend update per measurement set;
///  - `klt-vio`: KLT on the frames, one backend update per frame
///    (synchroniser trigger `track_time`);
///  - `haste-vio`: HASTE on the events, seeded at corners of the frames (or
///    of frames reconstructed from events), synchronised like eklt-vio;
///  - `tracks`: no frontend; feature tracks read from a file (e.g. the
///    simulator's truth/tracks.txt) with optional Gaussian pixel noise, to test
///    the backend in isolation.
/// PipelineOptions::forMethod() gives each method's defaults; a config file
/// and overrides are applied on top of them.

#include <cstdint>
#include <string>
#include <string_view>

#include "evio/core/eigen_types.h"
#include "evio/core/options.h"
#include "evio/estimator/backend/backend_options.h"
#include "evio/estimator/frontend/frontend.h"
#include "evio/estimator/frontend/synchronizer.h"
#include "evio/estimator/pipeline/health_monitor.h"
#include "evio/estimator/pipeline/method.h"

namespace evio::estimator {

/// How the filter state is initialised. Ground truth reaches the estimator
/// only when the caller asks for it (`evio estimate --init groundtruth`);
/// the default starts from the sensors alone.
///  - `groundtruth` (the paper's protocol, what campaigns use): position, velocity and attitude
///    of the body at the initialisation time from groundtruth.txt (T_W_C of
///    the event camera converted with the rig: T_W_B = T_W_C · T_B_C⁻¹;
///    velocity by a central difference of p_W_B over ±velocity_half_window_s),
///    zero biases, the backend's initial covariance.
///  - `static`: the backend initialises itself from the first still window of
///    backend.static_window_s of IMU readings (roll, pitch, gyroscope bias;
///    position and yaw zero, so the estimate lives in its own world frame and
///    must be aligned before comparing with ground truth).
/// The mode that ran is written in the estimate's config.yaml.
struct InitOptions {
  std::string mode = "static";           ///< static | groundtruth
  /// Initialise this long after the start of the data (the first IMU reading,
  /// or the first ground-truth pose if later), s.
  double start_offset_s = 0.0;
  /// Half-width of the central difference giving the initial velocity, s.
  double velocity_half_window_s = 0.01;
  /// With mode groundtruth: start from the truth plus an error drawn from the
  /// backend's initial covariance (backend.initial_sigma_*, stream of the
  /// run's seed), so that the initial error is a sample of the covariance the
  /// filter states, as a NEES study needs. Off: the truth exactly (the paper's
  /// protocol), an error of zero under a covariance that is not.
  bool perturb = false;
  /// With mode groundtruth: estimate the gyroscope bias from this long of
  /// tracks before the filter's first update (gyro_bias_window.h), s; 0: off
  /// (the initial state's bias and σ, backend.initial_sigma_bg_degps, stand).
  double gyro_bias_window_s = 0.0;
  /// Keyframe spacing inside that window, s.
  double gyro_bias_keyframe_s = 0.1;
  /// Test the window's IMU for rest first (backend.static_max_*_std bounds):
  /// at rest its mean readings give both biases (and the tilt) as one update
  /// of the initial state, with their covariance, instead of the tracks.
  bool gyro_bias_window_rest = true;
  /// Where the rest ends (backend/still_prefix.h): the window's IMU is cut
  /// into blocks of gyro_bias_window_rest_block_s and is still up to the
  /// first block whose mean moves; still throughout, the whole window is
  /// the rest, else a still prefix at least this long, s, is (the filter
  /// then starts at the prefix's end and takes the window's later inputs).
  /// A prefix's rest measurement carries the tests' allowances for what they
  /// could not see. 0: the spread test alone decides, on the whole window.
  double gyro_bias_window_rest_prefix_s = 0.1;
  /// Block length of the still-prefix test, s.
  double gyro_bias_window_rest_block_s = 0.05;
  /// Use the window's tracks once: the filter takes the tracks' bias with
  /// its covariance and skips the window's measurement sets (else it keeps
  /// the prior's σ and takes the window's tracks again).
  bool gyro_bias_window_tracks_once = false;
  /// The bias's σ the filter starts with when it takes the window's tracks
  /// again: "prior" (the initial state's, as if the window had not been
  /// estimated) or "window" (the window's estimate's covariance: the tracks
  /// then inform the bias twice wherever the filter updates inside the
  /// window).
  std::string gyro_bias_window_sigma = "prior";

  template <class V>
  void fields(V& v) {
    v("mode", mode, "static (from the IMU) or groundtruth (groundtruth.txt, only when asked for)");
    v("start_offset_s", start_offset_s, "initialise this long after the start of the data, s");
    v("velocity_half_window_s", velocity_half_window_s, "half-width of the velocity difference, s");
    v("perturb", perturb, "groundtruth: add an error drawn from the backend's initial covariance");
    v("gyro_bias_window_s", gyro_bias_window_s, "groundtruth: gyroscope bias from this long of tracks first, s (0: off)");
    v("gyro_bias_keyframe_s", gyro_bias_keyframe_s, "keyframe spacing in the gyroscope-bias window, s");
    v("gyro_bias_window_rest", gyro_bias_window_rest, "a window whose IMU is at rest gives both biases from its mean");
    v("gyro_bias_window_rest_prefix_s", gyro_bias_window_rest_prefix_s,
      "rest ends at the first block whose mean moves; a still prefix this long counts, s (0: spread test only)");
    v("gyro_bias_window_rest_block_s", gyro_bias_window_rest_block_s, "block length of the still-prefix test, s");
    v("gyro_bias_window_tracks_once", gyro_bias_window_tracks_once,
      "the filter takes the window's bias with its covariance and skips the window's tracks");
    v("gyro_bias_window_sigma", gyro_bias_window_sigma,
      "the bias's starting sigma when the window's tracks are replayed: prior or window");
  }
  void validate() const;
};

/// Calibration used when a sequence has no sensors.yaml (recorded
/// Event-Camera Dataset folders have calib.txt only): the camera comes from
/// calib.txt, everything else from here, and the IMU noise from the backend
/// options (accelerometer_noise_density, ...).
struct CalibrationOptions {
  /// T_B_C: camera (event and frame, the same DAVIS sensor) into body (IMU)
  /// frame, 16 numbers row-major.
  Mat4 T_B_C = Mat4::Identity();
  double gravity_mps2 = 9.81;            ///< magnitude of gravity, m/s²
  double time_offset_cam_imu_s = 0.0;    ///< t_imu = t_cam + offset, s
  double imu_rate_hz = 1000.0;           ///< nominal IMU rate (informational), Hz
  /// Sensor size in pixels; 0: the size of the first frame.
  int width = 0;
  int height = 0;

  template <class V>
  void fields(V& v) {
    v("T_B_C", T_B_C, "camera into body (IMU) frame, 4x4 row-major");
    v("gravity_mps2", gravity_mps2, "magnitude of gravity, m/s^2");
    v("time_offset_cam_imu_s", time_offset_cam_imu_s, "t_imu = t_cam + offset, s");
    v("imu_rate_hz", imu_rate_hz, "nominal IMU rate, Hz");
    v("width", width, "sensor width, px (0: from the first frame)");
    v("height", height, "sensor height, px (0: from the first frame)");
  }
  void validate() const;
};

/// The `tracks` method: feature tracks from a file (core/io/tracks_txt.h,
/// pixels of the event camera), grouped into measurement sets.
struct TracksInputOptions {
  /// Tracks file; relative paths are relative to the sequence folder.
  std::string file = "truth/tracks.txt";
  /// Gaussian noise σ added to each pixel coordinate, px (stream "track_noise" of the run seed).
  double noise_px = 0.0;
  /// Measurement sets per second of data time: the samples at the first file
  /// time at or after each multiple of 1/rate; 0: every time in the file.
  double rate_hz = 20.0;
  /// A track whose consecutive samples are further apart than this is split:
  /// it ends at the first sample and continues under a new id (the simulator's
  /// truth tracks skip the times a point is occluded or out of view), s.
  double max_gap_s = 0.05;

  template <class V>
  void fields(V& v) {
    v("file", file, "tracks file (relative to the sequence folder)");
    v("noise_px", noise_px, "Gaussian pixel noise sigma, px");
    v("rate_hz", rate_hz, "measurement sets per second (0: every file time)");
    v("max_gap_s", max_gap_s, "a longer gap within a track splits it, s");
  }
  void validate() const;
};

/// What is written besides trajectory.txt (estimate_files.h of experiments).
struct PipelineOutputOptions {
  bool covariance = true;          ///< trajectory_covariance.txt
  bool imu_state = true;           ///< imu_state.txt (p, q, v, biases of B)
  bool health = true;              ///< health.txt (innovations of each visual update)
  double timing_interval_s = 0.1;  ///< a timing.txt line at least this often (data time), s
  /// Clock of timing.txt's processing_s: `wall` (steady clock, what timing.txt
  /// specifies) or `cpu` (CPU time of the process, all threads: std::clock),
  /// which a machine shared with other work does not inflate.
  std::string timing_clock = "wall";
  /// Stop reading input once the filter diverged or failed (the outputs end there).
  bool stop_on_divergence = true;

  template <class V>
  void fields(V& v) {
    v("covariance", covariance, "write trajectory_covariance.txt");
    v("imu_state", imu_state, "write imu_state.txt");
    v("health", health, "write health.txt");
    v("timing_interval_s", timing_interval_s, "timing.txt line interval, s of data time");
    v("timing_clock", timing_clock, "wall or cpu: the clock of timing.txt");
    v("stop_on_divergence", stop_on_divergence, "stop at divergence or failure");
  }
  void validate() const;
};

struct PipelineOptions {
  std::string method = "eklt-vio";   ///< eklt-vio | klt-vio | haste-vio | tracks
  std::uint64_t seed = 1;            ///< seed of the run's random streams (track noise)
  FrontendOptions frontend;
  SynchronizerOptions sync;
  BackendOptions backend;
  InitOptions init;
  CalibrationOptions calibration;
  TracksInputOptions tracks;
  HealthOptions health;
  PipelineOutputOptions output;
  /// Run the backend, the health monitor and the writer on a thread of their
  /// own, overlapped with reading and tracking (items handed over in order
  /// through a ring of 64): the same output files, byte for byte.
  bool backend_thread = false;

  template <class V>
  void fields(V& v) {
    v("method", method, "eklt-vio, klt-vio, haste-vio or tracks");
    v("seed", seed, "seed of the run's random streams");
    v("frontend", frontend, "feature tracking frontend");
    v("sync", sync, "track synchroniser");
    v("backend", backend, "EKF backend");
    v("init", init, "initialisation");
    v("calibration", calibration, "calibration when the sequence has no sensors.yaml");
    v("tracks", tracks, "tracks input (method tracks)");
    v("health", health, "self-diagnosis without ground truth");
    v("output", output, "outputs");
    v("backend_thread", backend_thread, "backend, health monitor and writer on their own thread (same output)");
  }
  /// Throws evio::Error naming the field (nested fields with their path,
  /// e.g. "frontend.tracker: must be klt for method klt-vio").
  void validate() const;
  /// `method` parsed (method.h); throws evio::Error for an unknown name.
  Method methodKind() const;

  /// The defaults of `method`: eklt-vio → frontend.tracker eklt, sync.trigger
  /// events; klt-vio → frontend.tracker klt, sync.trigger track_time; tracks →
  /// the frontend is unused. Throws evio::Error for an unknown method.
  static PipelineOptions forMethod(std::string_view method);
};


}  // namespace evio::estimator

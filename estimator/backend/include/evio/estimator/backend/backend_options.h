#pragma once
/// @file backend_options.h
/// Parameters of the xVIO-style EKF backend with the reference defaults of
/// docs/algorithms.md#ekf-backend (DAVIS240 IMU noise) and the paper (M = 10,
/// N = 15), and the sensors the backend needs (from sensors.yaml).

#include <optional>
#include <string_view>

#include "evio/core/camera/camera.h"
#include "evio/core/options.h"
#include "evio/core/pose.h"
#include "evio/core/sensor_rig.h"
#include "evio/estimator/backend/imu_propagation.h"

namespace evio::estimator {

struct BackendOptions {
  // Sliding window and features -----------------------------------------------
  int window_size = 10;        ///< M: camera poses in the sliding window
  /// Keyframe spacing of the window, s: the pose cloned for a measurement set
  /// stays in the window only if it is at least this much later than the
  /// clone before it; otherwise it is marginalised when the next set arrives
  /// (its SLAM updates are kept, its MSCKF observations dropped). Frames at
  /// 20–22 Hz are all kept; event-based frontends, which update at 100–500
  /// Hz, get a window of the same span in time, so that MSCKF features and
  /// triangulated SLAM features have parallax (docs/algorithms.md#keyframe-window).
  /// 0: every measurement set's pose is kept (xVIO).
  double keyframe_interval_s = 0.04;
  int max_slam_features = 15;  ///< N: SLAM features in the state
  /// Image measurement noise σ_img in pixels, converted to normalised units by
  /// the mean focal length (σ_img / f). xVIO's 0.025 normalised ≈ 5 px at f ≈ 200 px.
  double sigma_img_px = 5.0;
  /// σ_img in normalised image coordinates (xVIO's unit); when > 0 it replaces
  /// sigma_img_px, so one setting serves cameras of any focal length.
  double sigma_img_normalized = 0.0;

  // IMU -------------------------------------------------------------------------
  /// Take the IMU noise densities from the rig (sensors.yaml) instead of the fields below.
  bool use_rig_imu_noise = true;
  double accelerometer_noise_density = 0.004316;  ///< σ_a, m/s²/√Hz (DAVIS240 reference)
  double accelerometer_random_walk = 0.0004316;   ///< σ_ba, m/s³/√Hz
  double gyroscope_noise_density = 0.0002;        ///< σ_g, rad/s/√Hz
  double gyroscope_random_walk = 0.00002;         ///< σ_bg, rad/s²/√Hz
  /// IMU outlier bound: a reading with ‖acc‖ above this (or non-finite) is
  /// replaced by the previous reading, m/s².
  double imu_max_acc_mps2 = 100.0;
  /// Gaps between IMU readings longer than this are counted (bridged by linear interpolation), s.
  double imu_max_gap_s = 0.05;
  /// A gap longer than this sets the status to failed, s.
  double imu_fail_gap_s = 1.0;

  // Initial uncertainty (docs/algorithms.md#divergence-and-failure) ------------------------------
  double initial_sigma_p_m = 0.0;          ///< position (0: exactly known; stored as 1e-12 m²)
  double initial_sigma_v_mps = 0.05;       ///< velocity, m/s
  double initial_sigma_theta_deg = 3.0;    ///< attitude, deg (all three axes)
  double initial_sigma_bg_degps = 6.0;     ///< gyroscope bias, deg/s
  double initial_sigma_ba_mps2 = 0.3;      ///< accelerometer bias, m/s²

  // SLAM features -----------------------------------------------------------------
  /// d_min: the depth prior is ρ0 = 1/(2 d_min), σ_ρ0 = 1/(4 d_min)
  /// (reference ρ0 = 1.3, σ 0.65 ⇔ d_min = 0.3846 m).
  double slam_min_depth_m = 0.3846;
  /// Depth prior from the map: a new feature that cannot be triangulated
  /// takes ρ0 = the median inverse depth, seen from its clone, of the points
  /// the filter has triangulated (the last map_prior_memory MSCKF features and
  /// triangulated SLAM initialisations) and of the SLAM features whose depth the
  /// data have fixed (σ_ρ ≤ map_prior_max_relative_sigma · ρ), with σ_ρ0 = ρ0/2
  /// (the fixed prior's shape), once at least map_prior_min_points are in
  /// front of the clone; before that, the fixed prior
  /// (docs/algorithms.md#depth-prior-from-the-map). The fixed prior fits one
  /// scene depth: a 2.5 m scene with a 1 m prior drove the ANEES into the
  /// thousands (docs/consistency.md "Keyframe window and triangulation").
  bool depth_prior_from_map = true;
  int map_prior_memory = 30;
  double map_prior_max_relative_sigma = 0.25;
  int map_prior_min_points = 3;
  int slam_min_track_length = 10;          ///< observations before a track may become SLAM
  /// Or a track of at least msckf_min_track_length observations spanning
  /// this long, s (0: off): ten observations at 20 Hz frames span 0.45 s,
  /// which an event tracker's track of a slow feature spans with fewer
  /// observations (docs/algorithms.md#slam-features). The floor of three is
  /// msckf_min_track_length: the shortest track the filter uses at all.
  double slam_min_track_span_s = 0.45;
  double slam_gate_probability = 0.95;     ///< Mahalanobis (χ², 2 dof) gate of SLAM updates
  int slam_max_gate_failures = 3;          ///< consecutive gate failures that remove a SLAM feature
  /// A SLAM feature's observation enters the update only when at least this
  /// long has passed since its last one did (or since it was initialised),
  /// s (0: every measurement set, the default). An event tracker gives a
  /// feature a position at every set (up to about 300 Hz), and its errors 10 ms
  /// apart are one error (correlation 0.8–0.9, docs/consistency.md
  /// "Consistency from a drawn initial error"); the skipped observations keep
  /// the feature alive but add no rows
  /// (docs/algorithms.md#correlated-measurements).
  double slam_update_interval_s = 0.0;
  /// Or when the feature has moved at least this far in the image since its
  /// last update, normalised image units (0: off): whether motion, which
  /// brings new edges under the tracker's patch, decorrelates its error
  /// better than time (measured: it does not, docs/consistency.md "A
  /// parameter set for the Mars rigs"). With both set, either lets an
  /// observation in; with only this, a feature that does not move is not
  /// updated again.
  double slam_update_min_displacement_normalized = 0.0;
  bool slam_triangulated_init = true;      ///< initialise from triangulation when the track fixes the depth
  /// A feature that takes a depth prior (fixed, map or range) takes it
  /// together with its track's observations in the window: the MAP (α, β, ρ)
  /// of track and prior, then the prior as one more row of the triangulated
  /// initialisation's split (docs/algorithms.md "Depth prior with the
  /// track"). Off (the default): the prior alone at the last observation,
  /// the track's earlier observations unused (xVIO); on, it is more accurate
  /// from the exact start but overconfident when the poses have drifted.
  bool slam_prior_init_with_track = false;
  /// The rotation-compensated disparity a track needs before it is taken
  /// with the prior, px (below: the prior alone).
  double slam_prior_track_min_parallax_px = 0.0;
  /// With slam_prior_init_with_track: instead of the refinement with the
  /// clones held at their estimates and the split, the feature takes the
  /// plain prior at its last observation and the track's earlier
  /// observations then enter as one update of clones and feature together.
  /// With slam_prior_track_iterations > 1 the update is iterated
  /// (re-linearised at each iterate): the MAP of the window's poses, the
  /// feature and the prior, with the filter's covariance as the poses' prior
  /// (a small bundle adjustment).
  bool slam_prior_track_update = false;
  /// Iterations of that update: 1 an EKF update linearised at the plain
  /// prior; more, Gauss–Newton iterations (stopping once a step changes the
  /// state by less than 1e-9).
  int slam_prior_track_iterations = 1;
  /// Add the covariance of the bilinear ρ·(clone error) term that the EKF's
  /// linearisation drops to each SLAM observation's noise
  /// (slamSecondOrderCovariance in slam_features.h): the inflation is large
  /// while a depth-prior feature's ρ is uncertain and vanishes as it converges.
  /// Off: on the backend's consistency scenario it lowers the NEES only from
  /// 8.86 to 8.47 at the true noise (docs/algorithms.md#second-order-depth-term).
  bool slam_second_order_noise = false;
  /// Track drift, px²/s: a tracker's error against the truth wanders like a
  /// random walk of this rate (measured by `evio evaluate-tracks`), which a
  /// SLAM feature's bearing (α, β) takes up as process noise between two
  /// measurement sets, P_αα += q Δt / f_x², P_ββ += q Δt / f_y²
  /// (docs/algorithms.md#track-drift). 0: a feature's bearing is fixed and
  /// every observation's error independent of the others.
  double slam_bearing_walk_px2_per_s = 0.0;
  /// Track errors as states (docs/algorithms.md "Track errors as states"):
  /// each SLAM feature carries the tracker's error e on it, a Gauss–Markov
  /// process with stationary σ (px per axis) and correlation time, so that
  /// consecutive observations share it instead of counting it again. 0: off.
  double slam_track_error_sigma_px = 0.0;
  double slam_track_error_time_s = 0.5;
  /// A shift the features share (docs/algorithms.md "A shift the features
  /// share"): an error common to every observation of one measurement set
  /// (the newest clone), z = π(h) + s + n, which averaging over features does not reduce,
  /// as a 2-vector state s (normalised units), a first-order Gauss–Markov
  /// process with stationary σ (px per axis) and correlation time. 0: off.
  double slam_image_shift_sigma_px = 0.0;
  double slam_image_shift_time_s = 0.05;
  /// How long after the filter's initialisation a SLAM candidate may take the
  /// fixed depth prior (ρ0 = 1/(2 d_min)) when neither a triangulation, the
  /// range finder nor the map gives its depth, s. Before that the track stays
  /// in the window, waiting for the map to know the scene's depth
  /// (docs/algorithms.md "Depth prior from the map"). 0: at once.
  double slam_fixed_prior_wait_s = 0.0;
  /// The scene's inverse depth ρ_s as a state (docs/algorithms.md "The scene's
  /// depth as a state"): every feature that takes the fixed prior shares the prior's
  /// error (the scene stands at one depth, ρ0 says another), which
  /// independent priors read as scale. With share c in (0, 1), ρ_s enters
  /// the state at the first fixed-prior feature as ρ0 with variance c σ_ρ0²,
  /// and each fixed-prior feature takes ρ = ρ_s + δ with var δ = (1 − c) σ_ρ0²
  /// and δ independent: the first has the fixed prior's marginal exactly,
  /// later ones start from what the filter has learnt of ρ_s. 0: off
  /// (independent fixed priors), the default: mixed results
  /// (docs/consistency.md "Depth priors that are wrong together").
  double slam_scene_depth_share = 0.0;
  /// ρ_s random-walks (the scene changes as the camera moves): its variance
  /// grows by c σ_ρ0² over this time, s.
  double slam_scene_depth_memory_s = 10.0;

  // MSCKF features ----------------------------------------------------------------
  /// Also use tracks lost before spanning the window (xVIO drops them).
  bool msckf_use_lost_tracks = false;
  /// A track with too little parallax to triangulate (xVIO drops it) still
  /// tells how the camera turned between its clones: its rows, linearised at
  /// the fixed depth prior with the depth projected out, constrain the
  /// clones' relative attitude (msckf_update.h rotationResidual;
  /// docs/algorithms.md "Rotation rows"). Off: such tracks are dropped.
  bool msckf_rotation_rows = false;
  int msckf_min_track_length = 3;          ///< fewer observations: not used (>= 2)
  /// Rotation-compensated disparity an MSCKF track needs before it is
  /// triangulated, px. xVIO's 30 px kept MSCKF features out of every scene
  /// farther than about 1 m (docs/algorithms.md#triangulation).
  double min_parallax_px = 10.0;
  /// The same for a SLAM feature's triangulated initialisation, px (xVIO's
  /// 30): below it the backend's NEES test finds the filter overconfident
  /// (a wrongly triangulated SLAM feature stays in the state; an MSCKF
  /// feature is used once).
  double slam_min_parallax_px = 30.0;
  /// Triangulate a track (MSCKF update, triangulated SLAM initialisation) only
  /// when its own observations fix the inverse depth better than the depth
  /// prior: σ_ρ from the triangulation (σ_img per coordinate) at most the
  /// σ of the prior the feature would take (the range finder's, else
  /// σ_ρ0 = 1/(4 d_min)); otherwise an MSCKF track counts as without
  /// parallax and a SLAM feature takes the depth prior.
  bool triangulate_when_better_than_prior = true;
  double msckf_gate_probability = 0.95;    ///< χ² gate of MSCKF features
  int triangulation_max_iterations = 10;   ///< Gauss–Newton iterations
  double triangulation_tolerance = 1e-5;   ///< relative step that ends Gauss–Newton
  double triangulation_min_depth_m = 0.05; ///< nearer triangulated points are rejected, m

  // Update -------------------------------------------------------------------------
  /// Covariance update: P − K S Kᵀ, symmetrised (the default), or the Joseph
  /// form (I − KH) P (I − KH)ᵀ + σ² K Kᵀ. With the optimal gain the two are
  /// equal (A Hᵀ = σ² K for A = (I − KH) P, so the Joseph form's last two
  /// terms cancel). The Joseph form is robust to the rounding of the gain
  /// (P stays positive semi-definite; without it the health check catches a
  /// P that is not) at three more O(n² m) products (backend CPU +18–21 %),
  /// and changed no campaign metric in its third digit over 110 EKLT-VIO
  /// and 110 KLT-VIO jobs (README "Real time").
  bool joseph_form = false;
  /// κ ≥ 1 for the visual update (SLAM and MSCKF rows): the gain keeps the
  /// rows' stated noise σ², the covariance takes κ σ²,
  /// P ← (I − K H) P (I − K H)ᵀ + κ σ² K Kᵀ (ekf_update.h). That is the
  /// covariance of the estimate when the rows' real noise is κ times what the
  /// gain assumes, as when a tracker's errors repeat over the rows the filter
  /// takes as independent. 1: the optimal update.
  double visual_covariance_factor = 1.0;
  /// Observability constraint (our addition, not in xVIO): the IMU transition
  /// is evaluated at the state before the updates (first-estimate Jacobians,
  /// Huang et al. 2010) and every measurement Jacobian is projected onto the
  /// complement of the unobservable global-yaw direction (observability-
  /// constrained EKF, Hesch et al. 2014), so the filter gains no spurious yaw
  /// information and stays consistent in rotation-only motion and hover.
  bool observability_constraint = true;
  /// Iterations of the visual update (1: EKF; more: iterated EKF re-linearising
  /// the SLAM observations, xVIO's iekf_iter). Measured on the six_dof test
  /// scenario: more iterations oscillate on depth-prior features (the bilinear
  /// ρ·Δp term) and make the filter diverge; keep 1.
  int iekf_iterations = 1;
  /// Iterations of the MSCKF rows in the visual update (1: each track
  /// triangulated and linearised once, at the prior). More: each track used
  /// is triangulated again at every iterate and its rows re-linearised there
  /// (an iterated EKF for the MSCKF part, the SLAM rows linearised once);
  /// not together with iekf_iterations > 1.
  int msckf_iterations = 1;

  // Timing ---------------------------------------------------------------------------
  /// The filter state is kept at most this far behind the newest IMU reading;
  /// measurements may arrive this late, s.
  double max_delay_s = 0.1;
  /// A measurement older than the filter state by at most this is applied at
  /// the filter state (the nearest buffered state); older ones are dropped, s.
  double max_late_s = 0.005;

  // Divergence ------------------------------------------------------------------------
  double max_velocity_mps = 100.0;  ///< a faster velocity estimate means divergence, m/s
  /// Filter time between two full positive semi-definiteness tests of the
  /// covariance, s. The full test is a Cholesky factorisation of the whole
  /// P, O(n³): after every item it cost 13–15 % of the backend's CPU on
  /// poster_6dof and mars_yard_circle. It runs at the first item after a
  /// start, at most this often afterwards, and once more at the end of the
  /// input; 0 runs it after every item. Every item still gets the O(n²)
  /// tests: finite entries, positive variances and every 2 × 2 principal
  /// minor, all of which the full test implies.
  double covariance_check_interval_s = 0.1;

  // Optional updates -------------------------------------------------------------------
  /// The laser range finder. The pipeline feeds the sequence's range.txt to
  /// Backend::addRange (range updates, xVIO's range-VIO: the scale of the
  /// SLAM features near the beam) only when this is set, and needs a range
  /// finder in sensors.yaml; in the backend the flag enables the depth
  /// priors below (readings given to addRange are range updates either way).
  bool use_range = false;
  /// With use_range, a SLAM feature that cannot be triangulated takes its
  /// depth prior from the latest range reading instead of slam_min_depth_m:
  /// its ray meets the level plane (normal along W's z) through the beam's
  /// hit point, ρ0 = 1/depth, σ_ρ0 = range_prior_relative_sigma · ρ0
  /// (terrain relief about the plane). 0 keeps the fixed prior.
  double range_prior_relative_sigma = 0.3;
  /// A reading older than this does not give priors, s.
  double range_prior_max_age_s = 0.25;
  /// Range-finder noise σ, m (0: the rig's noise_sigma_m).
  double range_sigma_m = 0.0;
  /// SLAM features whose ray is within this angle of the range beam define
  /// the terrain plane (at least 3 are needed), deg.
  double range_max_feature_angle_deg = 15.0;
  double zero_velocity_sigma_mps = 0.01;  ///< zero-velocity update noise σ, m/s

  // Static initialisation -----------------------------------------------------------------
  double static_window_s = 1.0;             ///< still IMU needed, s
  double static_max_acc_std_mps2 = 0.1;     ///< per-axis std of acc within the window, m/s²
  double static_max_gyro_std_radps = 0.02;  ///< per-axis std of gyro within the window, rad/s

  template <class V>
  void fields(V& v) {
    v("window_size", window_size, "M: camera poses in the sliding window");
    v("keyframe_interval_s", keyframe_interval_s,
      "a cloned pose closer than this to the one before it leaves the window at the next set, s (0: keep all)");
    v("max_slam_features", max_slam_features, "N: SLAM features in the state");
    v("sigma_img_px", sigma_img_px, "image measurement noise, px");
    v("sigma_img_normalized", sigma_img_normalized, "if > 0: image noise in normalised units (replaces sigma_img_px)");
    v("use_rig_imu_noise", use_rig_imu_noise, "IMU noise from sensors.yaml");
    v("accelerometer_noise_density", accelerometer_noise_density, "m/s^2/sqrt(Hz)");
    v("accelerometer_random_walk", accelerometer_random_walk, "m/s^3/sqrt(Hz)");
    v("gyroscope_noise_density", gyroscope_noise_density, "rad/s/sqrt(Hz)");
    v("gyroscope_random_walk", gyroscope_random_walk, "rad/s^2/sqrt(Hz)");
    v("imu_max_acc_mps2", imu_max_acc_mps2, "IMU outlier bound on |acc|, m/s^2");
    v("imu_max_gap_s", imu_max_gap_s, "IMU gaps counted above, s");
    v("imu_fail_gap_s", imu_fail_gap_s, "IMU gap that fails the filter, s");
    v("initial_sigma_p_m", initial_sigma_p_m, "initial position sigma, m");
    v("initial_sigma_v_mps", initial_sigma_v_mps, "initial velocity sigma, m/s");
    v("initial_sigma_theta_deg", initial_sigma_theta_deg, "initial attitude sigma, deg");
    v("initial_sigma_bg_degps", initial_sigma_bg_degps, "initial gyro bias sigma, deg/s");
    v("initial_sigma_ba_mps2", initial_sigma_ba_mps2, "initial accel bias sigma, m/s^2");
    v("slam_min_depth_m", slam_min_depth_m, "d_min of the depth prior, m");
    v("depth_prior_from_map", depth_prior_from_map, "depth prior from the median depth of the triangulated points");
    v("map_prior_memory", map_prior_memory, "latest triangulated points the map's depth remembers");
    v("map_prior_max_relative_sigma", map_prior_max_relative_sigma,
      "a SLAM feature counts for the map's depth when its sigma_rho / rho is at most this");
    v("map_prior_min_points", map_prior_min_points, "points in front of the camera the map's depth needs");
    v("slam_min_track_length", slam_min_track_length, "observations before SLAM");
    v("slam_min_track_span_s", slam_min_track_span_s, "or a track spanning this long, s (0: off)");
    v("slam_gate_probability", slam_gate_probability, "SLAM Mahalanobis gate probability");
    v("slam_max_gate_failures", slam_max_gate_failures, "gate failures removing a SLAM feature");
    v("slam_update_interval_s", slam_update_interval_s,
      "least time between two updates of one SLAM feature, s (0: every measurement set)");
    v("slam_update_min_displacement_normalized", slam_update_min_displacement_normalized,
      "or least image motion since its last update, normalised (0: off)");
    v("slam_triangulated_init", slam_triangulated_init, "SLAM init from triangulation when possible");
    v("slam_prior_init_with_track", slam_prior_init_with_track,
      "a depth-prior SLAM initialisation also uses the track's observations in the window");
    v("slam_prior_track_min_parallax_px", slam_prior_track_min_parallax_px,
      "rotation-compensated disparity a track needs to be taken with the depth prior, px");
    v("slam_prior_track_update", slam_prior_track_update,
      "the track's earlier observations enter as an update after the plain prior");
    v("slam_prior_track_iterations", slam_prior_track_iterations, "iterations of that update (1: EKF)");
    v("slam_second_order_noise", slam_second_order_noise,
      "SLAM observation noise includes the second-order inverse-depth term");
    v("slam_fixed_prior_wait_s", slam_fixed_prior_wait_s,
      "time after initialisation before a SLAM candidate may take the fixed depth prior, s");
    v("slam_scene_depth_share", slam_scene_depth_share,
      "share of the fixed depth prior's variance in the scene inverse depth state (0: off)");
    v("slam_scene_depth_memory_s", slam_scene_depth_memory_s,
      "time over which the scene inverse depth's variance grows by its prior share, s");
    v("slam_bearing_walk_px2_per_s", slam_bearing_walk_px2_per_s,
      "track drift: random-walk rate of a SLAM feature's bearing, px^2/s");
    v("slam_track_error_sigma_px", slam_track_error_sigma_px,
      "track errors as states: stationary sigma of a SLAM feature's track error, px (0: off)");
    v("slam_track_error_time_s", slam_track_error_time_s, "track errors as states: correlation time, s");
    v("slam_image_shift_sigma_px", slam_image_shift_sigma_px,
      "an image shift every observation of a set shares, as a state: stationary sigma per axis, px (0: off)");
    v("slam_image_shift_time_s", slam_image_shift_time_s, "that shift's correlation time, s");
    v("msckf_use_lost_tracks", msckf_use_lost_tracks, "use tracks lost before spanning the window");
    v("msckf_min_track_length", msckf_min_track_length, "minimum MSCKF track length");
    v("msckf_rotation_rows", msckf_rotation_rows, "tracks without parallax give rows at the depth prior, depth projected out");
    v("min_parallax_px", min_parallax_px, "rotation-compensated disparity for an MSCKF triangulation, px");
    v("slam_min_parallax_px", slam_min_parallax_px, "rotation-compensated disparity for a triangulated SLAM initialisation, px");
    v("triangulate_when_better_than_prior", triangulate_when_better_than_prior,
      "triangulate only tracks whose inverse depth sigma is below the depth prior's");
    v("msckf_gate_probability", msckf_gate_probability, "MSCKF chi2 gate probability");
    v("triangulation_max_iterations", triangulation_max_iterations, "Gauss-Newton iterations");
    v("triangulation_tolerance", triangulation_tolerance, "relative Gauss-Newton step tolerance");
    v("triangulation_min_depth_m", triangulation_min_depth_m, "nearest triangulated depth, m");
    v("joseph_form", joseph_form, "Joseph-form covariance update");
    v("visual_covariance_factor", visual_covariance_factor,
      "visual update: the covariance takes the rows' noise as this factor times the gain's (1: optimal)");
    v("observability_constraint", observability_constraint, "keep global yaw unobservable (FEJ transition, OC updates)");
    v("iekf_iterations", iekf_iterations, "iterations of the visual update (1: EKF)");
    v("msckf_iterations", msckf_iterations, "iterations of the MSCKF rows, re-triangulated at each (1: EKF)");
    v("max_delay_s", max_delay_s, "filter lag behind the newest IMU reading, s");
    v("max_late_s", max_late_s, "late measurements applied at the filter state, s");
    v("max_velocity_mps", max_velocity_mps, "velocity bound for divergence, m/s");
    v("covariance_check_interval_s", covariance_check_interval_s,
      "filter time between full covariance (Cholesky) tests, s (0: every item)");
    v("use_range", use_range, "use the laser range finder (range.txt)");
    v("range_prior_relative_sigma", range_prior_relative_sigma, "relative sigma of the range depth prior (0: off)");
    v("range_prior_max_age_s", range_prior_max_age_s, "oldest range reading for a depth prior, s");
    v("range_sigma_m", range_sigma_m, "range noise, m (0: rig)");
    v("range_max_feature_angle_deg", range_max_feature_angle_deg, "features near the beam, deg");
    v("zero_velocity_sigma_mps", zero_velocity_sigma_mps, "zero-velocity noise, m/s");
    v("static_window_s", static_window_s, "still IMU window, s");
    v("static_max_acc_std_mps2", static_max_acc_std_mps2, "stillness bound on acc std, m/s^2");
    v("static_max_gyro_std_radps", static_max_gyro_std_radps, "stillness bound on gyro std, rad/s");
  }
  /// Throws evio::Error naming the field.
  void validate() const;

  /// The IMU noise densities to use: the rig's when use_rig_imu_noise, else the fields.
  ImuNoiseDensities imuNoise(const ImuSensor& rig_imu) const;
};

/// What the backend needs to know about the sensors.
struct BackendSensors {
  Camera camera;                                   ///< the camera the measurements come from
  Pose T_B_C;                                      ///< camera into body (IMU) frame
  double gravity_mps2 = 9.81;                      ///< magnitude of gravity, along −z of W
  ImuSensor imu;                                   ///< noise densities (Kalibr names)
  std::optional<RangeFinderSensor> range_finder;   ///< when the rig has one
  TimeNs time_offset_cam_imu_ns = 0;               ///< t_imu = t_cam + offset

  /// From a rig: the camera named `camera_name`, or the first event camera
  /// (else the first camera) when empty. Throws evio::Error for an unknown name.
  static BackendSensors fromRig(const SensorRig& rig, std::string_view camera_name = "");
};

}  // namespace evio::estimator

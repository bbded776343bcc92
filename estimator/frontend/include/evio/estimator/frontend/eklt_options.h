#pragma once
/// @file eklt_options.h
/// Parameters of the EKLT tracker with the reference defaults
/// (docs/algorithms.md#eklt; 6-DOF sequences).

#include <string>

#include "evio/core/options.h"
#include "evio/estimator/frontend/davis_thresholds.h"

namespace evio::estimator {

struct EkltOptions {
  // Detection (Harris corners on frames).
  int max_features = 60;             ///< corners detected up to this many live features
  int min_features = 45;             ///< re-detect on a frame when fewer are alive
  double harris_quality_level = 0.3; ///< relative to the strongest response
  double harris_k = 0.04;            ///< Harris k
  int harris_block_size = 3;         ///< Harris window, px
  double min_distance_px = 9.0;      ///< between corners and around live patches

  // Patch and batches.
  int patch_size_px = 19;              ///< odd patch side P (17 on rotation-only; original EKLT 25)
  double batch_displacement_px = 0.6;  ///< d: a batch holds about the events of a d-px motion
  /// C in the batch size N = clamp(Σ_u |d ∇L(u)·v| / C, min, max): the
  /// contrast threshold of the event camera (log units). With ∇L the true
  /// log-image derivative (log_image.h) this makes N the number of events a
  /// d-px motion produces. 0 (default): the sensor's own, the mean of the
  /// contrast_threshold_pos/neg its calibration states (sensors.yaml camera
  /// parameters; resolveSensorParameters in frontend.h), else
  /// kDavis240cContrastThreshold. A C below the sensor's makes batches span
  /// more motion than d: on the calibrated DAVIS240C (C 0.5/0.38) the former
  /// fixed 0.25 gave 1.8× longer batches, and EKLT tracks drifted off at
  /// every reversal of the hand-held motion (docs/consistency.md "EKLT on
  /// real-like events").
  double batch_contrast_threshold = 0.0;
  int batch_min_events = 5;            ///< lower clamp of the batch size
  int batch_max_events = 500;          ///< upper clamp of the batch size

  // Optimisation.
  std::string solver = "lm";           ///< "lm" (hand-written, hot path) or "ceres" (reference)
  int max_iterations = 25;             ///< per batch
  /// The optimiser's sums over the patch in single precision, sixteen pixels
  /// at a time (eklt_cost.h EkltBatch::single_precision), else in double
  /// precision four at a time; the same bits on every x86-64 CPU either way.
  bool single_precision = true;
  /// Stop when |Δcost| ≤ tol · cost (Ceres' function_tolerance; Ceres'
  /// default is 1e-6). Near the minimum the Gauss–Newton steps shrink by a
  /// factor r per iteration (about 0.3 here), so the solve stops with an
  /// excess cost of at most r² tol cost / (1 − r²): with the covariance
  /// model below (σ_r² = 2 cost / (P² − 4)) a position error of at most
  /// r √((P² − 4) tol / (1 − r²)) ≈ 0.2 of the fit's own σ at 1e-3, before the
  /// σ floor of 2 px. 1e-3 stays within 0.01 px of Ceres run with its
  /// defaults on the same batches (eklt_solver_test.cpp); against the former 1e-4 it takes 18–25 %
  /// fewer solver iterations per campaign cell with every cell's accuracy
  /// statistically unchanged (experiments/campaigns/eklt_tolerance.yaml;
  /// mars_rotation's median, outside its quartiles on ten seeds, checked on
  /// twenty more: eklt_tolerance_seeds.yaml; README "Real time").
  double function_tolerance = 1e-3;
  /// Stop when ‖δp‖ ≤ tol · (‖p‖ + tol) (Ceres' parameter_tolerance; Ceres'
  /// default 1e-8). ‖p‖ is dominated by the template position (~10² px), so
  /// 1e-5 stops at steps of about 10⁻³ px.
  double parameter_tolerance = 1e-5;
  double min_tracking_quality = 0.6;   ///< lost below this 1 − cost/2 (the only outlier test)
  /// Motion reversal: when a batch's solution has quality below this (or
  /// moves implausibly far, max_batch_shift_px), solve again from the
  /// reversed flow direction φ + π and keep the better plausible one
  /// (0: only on implausible moves). The cost is not convex in φ: the predicted increment
  /// −∇L·v changes sign when the motion reverses, and from the old φ the
  /// optimiser settles in a wrong minimum (eklt_tracker_test
  /// ReversingMotionIsFollowed). The re-solve starts where ρ < 0 and
  /// nearly always runs to max_iterations; below quality 0.7 it wins 12–41 %
  /// of the time, between 0.7 and 0.8 only 5–6 % (poster_6dof). 0.7 against
  /// the former 0.8: 11–30 % fewer solver iterations per campaign cell, every
  /// cell's median error within its former quartiles (README "Real time").
  double reversal_quality = 0.7;
  /// A batch holds the events of about batch_displacement_px of motion, so a
  /// solution that moves the feature further than this from its prediction
  /// is a wrong minimum: re-solved from φ + π, and dropped (the feature keeps
  /// its position, the events are discarded) if that is no better. 0.6 px
  /// batches; 3 px is five batches' motion.
  double max_batch_shift_px = 3.0;
  double lost_border_px = 0.0;         ///< lost when the centre comes closer than this to the image edge

  // Measurement covariance (eklt_cost.h ekltPositionCovariance).
  /// Attach to each track point the covariance of its position from the
  /// curvature of the cost at the solution (else none: the backend's σ_img).
  /// On by default: with repeated points dropped, the lowest median error
  /// on poster, shapes and boxes on the calibrated sensors (campaign
  /// eklt_variants, docs/consistency.md "EKLT on real-like events").
  bool position_covariance = true;
  /// Floor of the position σ along any direction, px. The curvature sees
  /// only the noise of one batch (0.05–0.5 px); a track's error is mostly
  /// what persists from batch to batch (template drift, the bias and latency
  /// of the event model), which the filter would otherwise count again at
  /// every update. Chosen by the pose ANEES on poster_6dof seeds 1–5
  /// (docs/consistency.md "Consistency"): 0.2 px gives ANEES in the
  /// thousands, 1 px 6.9, 2 px 5.1 (with repeats dropped 4.4; bounds
  /// [3.36, 9.40]).
  double position_sigma_min_px = 2.0;
  /// Raise the floor in proportion for fits worse than this cost, up to the
  /// cap (eklt_cost.h ekltSigmaFloor: min(σ_min · max(1, cost / ref), σ_max));
  /// 0: the same floor for every point. The error's variance grows as the
  /// cost squared; a reference at the median cost of the rig's points keeps
  /// the typical point at σ_min (docs/consistency.md "A covariance floor
  /// that follows the fit": 0.24 indoors, 0.33 on the Mars rigs, from seed
  /// 101).
  double position_sigma_cost_ref = 0.0;
  /// Cap of the position σ, px: the directions the patch does not constrain
  /// (along a straight edge) get this σ (the former fixed σ_img, 5 px).
  double position_sigma_max_px = 5.0;
  /// Time constant of the track error stated with every point
  /// (TrackPoint::error_time_s), s; 0: independent from point to point. The
  /// backend weighs a SLAM feature's observations by it (docs/algorithms.md
  /// "SLAM observations weighted by their effective number"). Measured on
  /// EKLT's tracks against the truth: correlation 0.83 at 10 ms on the Mars
  /// circle (τ ≈ 54 ms), 0.89 on the poster (τ ≈ 86 ms). The errors are not
  /// first-order (0.75 at 0.1 s on the circle): τ fitted at 10 ms says how
  /// alike consecutive points are, not how long the slow part lasts.
  double error_time_s = 0.0;

  // Bootstrap (KLT between the detection frame and the next frame).
  int bootstrap_window_px = 20;        ///< Lucas–Kanade window side
  int bootstrap_pyramid_levels = 3;    ///< pyramid levels (OpenCV maxLevel = levels − 1)

  // Prediction and images.
  bool imu_prediction = false;         ///< predict each batch's start from the gyro (needs IMU and T_B_C)
  /// Use the gyro's prediction for a batch only when it moves the feature at
  /// least this far from its last position, px (0: on every batch). A batch
  /// is sized for batch_displacement_px of motion; a feature the gyro moves
  /// much farther between batches is one whose pixels fire fewer events per
  /// edge than the size assumed (fast motion, the refractory period), where
  /// a start at the last position is pixels behind. Below the gate the batch
  /// starts, and its plausibility window is centred, at the last position.
  double imu_prediction_min_shift_px = 0.0;
  /// With imu_prediction, add each feature's own translational image
  /// velocity to the gyro's rotation, s (0: rotation only). The gyro
  /// explains the image motion of a camera that only turns; what a track
  /// moves beyond it is the translation's flow, which changes with the
  /// feature's depth. It is the least-squares slope over the feature's last
  /// points within this window of its derotated path: the sum of each
  /// accepted step minus the gyro's rotation over that step
  /// (track_velocity.h). At most 1 s.
  double imu_prediction_translation_window_s = 0.0;
  double log_offset = 0.01;            ///< L = log(I/255 + offset) for 8-bit frames

  template <class V>
  void fields(V& v) {
    v("max_features", max_features, "detect up to this many live features");
    v("min_features", min_features, "re-detect when fewer features are alive");
    v("harris_quality_level", harris_quality_level, "Harris quality level");
    v("harris_k", harris_k, "Harris k");
    v("harris_block_size", harris_block_size, "Harris block size, px");
    v("min_distance_px", min_distance_px, "minimum distance between features, px");
    v("patch_size_px", patch_size_px, "odd patch side, px");
    v("batch_displacement_px", batch_displacement_px, "motion per batch, px");
    v("batch_contrast_threshold", batch_contrast_threshold, "contrast threshold in the batch size (0: the sensor's)");
    v("batch_min_events", batch_min_events, "smallest batch");
    v("batch_max_events", batch_max_events, "largest batch");
    v("solver", solver, "lm or ceres");
    v("max_iterations", max_iterations, "optimiser iterations per batch");
    v("single_precision", single_precision, "optimiser sums in single precision, sixteen pixels at a time");
    v("function_tolerance", function_tolerance, "relative cost change that stops the optimiser");
    v("parameter_tolerance", parameter_tolerance, "relative step that stops the optimiser");
    v("min_tracking_quality", min_tracking_quality, "lost below this tracking quality");
    v("reversal_quality", reversal_quality, "re-solve from the reversed flow direction below this quality (0: never)");
    v("max_batch_shift_px", max_batch_shift_px, "largest plausible move of a feature in one batch, px");
    v("lost_border_px", lost_border_px, "lost this close to the image edge, px");
    v("position_covariance", position_covariance, "attach the position covariance from the cost curvature");
    v("position_sigma_min_px", position_sigma_min_px, "floor of the position sigma, px");
    v("position_sigma_cost_ref", position_sigma_cost_ref, "cost above which the floor grows (0: fixed floor)");
    v("position_sigma_max_px", position_sigma_max_px, "cap of the position sigma, px");
    v("error_time_s", error_time_s, "time constant of the track error stated with each point, s (0: independent)");
    v("bootstrap_window_px", bootstrap_window_px, "bootstrap KLT window, px");
    v("bootstrap_pyramid_levels", bootstrap_pyramid_levels, "bootstrap KLT pyramid levels");
    v("imu_prediction", imu_prediction, "predict feature positions from the gyro");
    v("imu_prediction_min_shift_px", imu_prediction_min_shift_px,
      "use the gyro prediction only when it moves the feature this far, px (0: always)");
    v("imu_prediction_translation_window_s", imu_prediction_translation_window_s,
      "add the feature's translational velocity fitted over this window to the gyro prediction, s (0: rotation only)");
    v("log_offset", log_offset, "offset in log(I/255 + offset)");
  }

  void validate() const;
};

}  // namespace evio::estimator

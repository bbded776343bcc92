#pragma once
/// @file haste_options.h
/// Parameters of the HASTE tracker (Alzugaray & Chli, "Asynchronous
/// multi-hypothesis tracking of features with event cameras", 3DV 2019;
/// "HASTE: multi-Hypothesis Asynchronous Speeded-up Tracking of Events",
/// BMVC 2020) with the defaults of the authors' reference implementation
/// (github.com/ialzugaray/haste: 31 px patch, window of 193 events = 1 +
/// 2⌊0.2·31²/2⌋, 11 hypotheses of ±1 px and ±4°, margin 0.05, template
/// update 0.1) and the variant HASTE-VIO defaults to in the EKLT-VIO code
/// release (its xVIO library's x/haste/haste_tracker, NASA/JPL 2021:
/// haste_difference_star). Seeding follows that release too: Harris corners on frames (the same detector as EKLT),
/// θ = 0, re-detected on a frame when too few features are alive
/// (docs/algorithms.md#haste).

#include <string>

#include "evio/core/options.h"

namespace evio::estimator {

/// The score of a hypothesis (haste_feature.h gives the equations).
enum class HasteVariant {
  kCorrelation,      ///< Gaussian-weighted correlation with the template (cached samples)
  kCorrelationStar,  ///< uniform-weight correlation, updated in O(1) per event and hypothesis
  kDifference,       ///< −‖template − event model‖², recomputed from the window every event
  kDifferenceStar,   ///< the same score updated in O(1) per event and hypothesis (default)
};

/// "haste_correlation" | "haste_correlation_star" | "haste_difference" |
/// "haste_difference_star"; throws evio::Error naming `variant` otherwise.
HasteVariant parseHasteVariant(const std::string& name);

struct HasteOptions {
  // The hypothesis tracker (per feature).
  std::string variant = "haste_difference_star";  ///< see HasteVariant
  int patch_size_px = 31;            ///< odd patch side P; events within (P − 1)/2 px of the state count
  /// Window size N = 1 + 2⌊f·P²/2⌋ events (the reference's "texture factor" f).
  double window_factor = 0.2;
  double margin = 0.05;              ///< jump when (S_best − S_null) > margin·(S_best − S_worst)
  double template_update = 0.1;      ///< weight of the middle event added to the template per event
  double step_px = 1.0;              ///< translation step of the hypotheses, px
  double step_deg = 4.0;             ///< rotation step of the hypotheses, degrees

  // Seeding (Harris corners on frames, as the EKLT-VIO release seeds HASTE).
  int max_features = 60;             ///< seed up to this many live features
  int min_features = 45;             ///< seed on a frame when fewer are alive
  double harris_quality_level = 0.3; ///< relative to the strongest response
  double harris_k = 0.04;            ///< Harris k
  int harris_block_size = 3;         ///< Harris window, px
  double min_distance_px = 9.0;      ///< between seeds and around live features
  /// Take the first half of the window from the events just before the seed
  /// (the reference's centred initialisation), so the first state is at the
  /// seed's time rather than N/2 events later.
  bool centered_initialization = true;
  int history_events = 32768;        ///< recent events kept for the centred initialisation
  double seed_timeout_s = 1.0;       ///< a seed that has not filled its window in this time is dropped

  /// Send a new state at most once per window span (the time the window's N
  /// events cover, the state's own time support); a jump within it is sent
  /// when the span has passed. Off: every jump is a track point. The
  /// synchroniser extrapolates from a track's last two points, and two jumps
  /// a few µs apart would give it a velocity of px per µs.
  bool one_point_per_window = true;

  // Ending tracks.
  double lost_border_px = 15.0;      ///< lost when the state comes closer than this to the image edge
  /// Time constant of the track error stated with every point, s (0:
  /// independent; as EkltOptions::error_time_s).
  double error_time_s = 0.0;
  /// σ of each point's position stated with every point, px per axis (0:
  /// none, the backend's σ_img; as KltOptions::position_sigma_px).
  double position_sigma_px = 0.0;

  template <class V>
  void fields(V& v) {
    v("variant", variant, "haste_correlation, haste_correlation_star, haste_difference or haste_difference_star");
    v("patch_size_px", patch_size_px, "odd patch side, px");
    v("window_factor", window_factor, "window size N = 1 + 2 floor(f P^2 / 2) events");
    v("margin", margin, "state-jump margin on the normalised scores");
    v("template_update", template_update, "template update weight of the middle event");
    v("step_px", step_px, "translation step of the hypotheses, px");
    v("step_deg", step_deg, "rotation step of the hypotheses, degrees");
    v("max_features", max_features, "seed up to this many live features");
    v("min_features", min_features, "seed when fewer features are alive");
    v("harris_quality_level", harris_quality_level, "Harris quality level");
    v("harris_k", harris_k, "Harris k");
    v("harris_block_size", harris_block_size, "Harris block size, px");
    v("min_distance_px", min_distance_px, "minimum distance between features, px");
    v("centered_initialization", centered_initialization, "first half of the window from events before the seed");
    v("history_events", history_events, "recent events kept for the centred initialisation");
    v("seed_timeout_s", seed_timeout_s, "drop a seed whose window is not full after this long, s");
    v("one_point_per_window", one_point_per_window, "send a new state at most once per window time span");
    v("lost_border_px", lost_border_px, "lost this close to the image edge, px");
    v("error_time_s", error_time_s, "time constant of the track error stated with each point, s (0: independent)");
    v("position_sigma_px", position_sigma_px, "position sigma stated with each point, px (0: none, the backend's sigma_img)");
  }

  void validate() const;
  /// N for these options.
  int windowSize() const;
};

}  // namespace evio::estimator

#pragma once
/// @file haste_feature.h
/// One HASTE feature: a multi-hypothesis patch tracker fed one event at a
/// time (Alzugaray & Chli, 3DV 2019 and BMVC 2020; docs/algorithms.md#haste).
///
/// State s = (t, x, y, θ): the patch centre in px (distorted image
/// coordinates) and its rotation. An event e = (ex, ey) is in range when
/// |e − (x, y)| < h, h = (P − 1)/2, and lands in the patch of hypothesis
/// (x', y', θ') at
///     u = R(θ')ᵀ (e − (x', y')) + (h, h),
/// i.e. u_x = c·dx + s·dy + h, u_y = −s·dx + c·dy + h (c = cos θ', s = sin θ').
/// The window holds the last N events in range (ring buffer, oldest first).
///
/// Template T (P × P): the window splatted (bilinear) at the seed state
/// once N events have arrived; after every event the window's middle event
/// is added with weight template_update·w_mid. The scores compare the window
/// with the reference R̂ = T/ΣT, taken from T at the start and at every
/// state jump (between jumps R̂ is fixed, as in the reference star forms).
///
/// Hypotheses: the state and its 10 neighbours (±step_px in x, in y, the
/// 4 diagonals, ±step_deg in θ; translations in image axes). Scores S_h:
///  - correlation:       S_h = Σ_k g_k R̂(u_h(e_k)), g Gaussian over window position k
///                        (σ = N/6, Σg = 1); samples cached per event, O(N) per event
///  - correlation_star:  S_h = (1/N) Σ_k R̂(u_h(e_k)), O(1) per event
///  - difference:        S_h = −Σ_pixels (R̂ − M_h/N)², M_h = Σ_k splat(u_h(e_k)),
///                        recomputed every event, O(N + P²)
///  - difference_star:   the same S_h with D_h = R̂ − M_h/N kept and only the
///                        2×2 cells of the new and the dropped event updated, O(1)
/// A bilinear sample or splat at u counts only when all four taps are in the
/// patch (0 ≤ u < P − 1 on both axes), the same rule in all variants.
///
/// After each event: b = argmax S, w = argmin S; the state jumps to
/// hypothesis b ≠ null when S_b > S_null and (S_b − S_null) > margin·(S_b − S_w);
/// the hypotheses are then re-centred on it and their scores recomputed from
/// the window. The state's time is the middle event's.
///
/// Memory is fixed at construction; addEvent allocates nothing.

#include <array>
#include <cstdint>
#include <vector>

#include "evio/core/time.h"
#include "evio/estimator/frontend/haste_options.h"

namespace evio::estimator {

struct HasteState {
  TimeNs t_ns = 0;
  double x = 0.0;      ///< px
  double y = 0.0;      ///< px
  double theta = 0.0;  ///< rad
};

class HasteFeature {
 public:
  static constexpr int kHypotheses = 11;
  static constexpr int kNull = 0;

  /// What one event did.
  enum class Update : std::uint8_t {
    kOutOfRange,  ///< not within h of the state: ignored
    kFilling,     ///< stored; the window is not full yet
    kStarted,     ///< the window just filled: template built, first state
    kRegular,     ///< scores updated, the state stays
    kJump,        ///< the state moved to another hypothesis
  };

  explicit HasteFeature(const HasteOptions& options);

  /// Empties the window and puts the state at `seed` (not yet started).
  void reset(const HasteState& seed);
  bool inRange(double ex, double ey) const;
  Update addEvent(TimeNs t_ns, double ex, double ey);

  bool started() const { return started_; }
  const HasteState& state() const { return hypotheses_[kNull]; }
  /// Events stored so far (≤ N before the start, N after).
  int windowCount() const { return count_; }
  /// Time between the oldest and the newest event of the window (0 before the start).
  TimeNs windowSpanNs() const {
    return started_ ? et_[static_cast<std::size_t>(ringIndex(n_ - 1))] - et_[static_cast<std::size_t>(head_)] : 0;
  }
  int windowSize() const { return n_; }

  /// Hypothesis h and its incrementally maintained score.
  const HasteState& hypothesis(int h) const { return hypotheses_[static_cast<std::size_t>(h)]; }
  double score(int h) const { return scores_[static_cast<std::size_t>(h)]; }
  /// S_h computed from the window and R̂ alone (no cache): the check for score().
  double scoreFromScratch(int h) const;

 private:
  struct Rot {
    double c = 1.0, s = 0.0;
  };
  void start();
  void jumpTo(int h);
  void centreHypotheses(const HasteState& centre);
  void refreshReference();
  void initialiseScores();
  void updateScores(double new_x, double new_y, double old_x, double old_y);
  void updateTemplate();
  int bestHypothesis() const;
  void patchPoint(int h, double ex, double ey, double* ux, double* uy) const;
  double sample(const std::vector<double>& patch, double ux, double uy) const;
  void splat(std::vector<double>& patch, double ux, double uy, double weight) const;
  void updateDifference(int h, double ux, double uy, double increment);
  double modelDifferenceScore(int h);
  /// Ring index of window position k (0 = oldest).
  int ringIndex(int k) const { return (head_ + k) % n_; }

  HasteVariant variant_;
  int p_;        // patch side P
  double half_;  // h
  int n_;        // window size N
  double margin_;
  double template_update_;
  std::array<HasteState, kHypotheses> offsets_{};  // (dx, dy, dθ) per hypothesis
  std::array<HasteState, kHypotheses> hypotheses_{};
  std::array<Rot, kHypotheses> rot_{};
  std::array<double, kHypotheses> scores_{};
  bool started_ = false;

  // Window: ring of N events, head_ = oldest once full.
  std::vector<double> ex_, ey_;
  std::vector<TimeNs> et_;
  int count_ = 0;
  int head_ = 0;
  std::vector<double> gauss_;  // g_k by window position (correlation)
  double uniform_ = 0.0;       // 1/N

  std::vector<double> template_;   // T, P²
  std::vector<double> reference_;  // R̂ = T/ΣT at the last start or jump
  // Per-variant caches.
  std::vector<double> samples_;      // correlation: R̂(u_h(e)) per hypothesis × ring slot
  std::vector<double> differences_;  // difference(_star): D_h per hypothesis × P²
};

}  // namespace evio::estimator

#pragma once
/// @file msckf_updater.h
/// MSCKF features (updater.h; the measurement model: msckf_update.h): each
/// chosen track is triangulated, linearised over its clones, projected on the
/// left null space of its point Jacobian and χ²-gated; the rows go into the
/// backend's stacked update. A track is used at most once.

#include <vector>

#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/feature_selection.h"
#include "evio/estimator/backend/updater.h"

namespace evio::estimator {

class MsckfUpdater : public Updater {
 public:
  /// sigma2: σ_z² of one normalised image coordinate; chi2: the MSCKF gate's quantiles.
  MsckfUpdater(const UpdaterContext& context, const Camera& camera, double sigma2, const Chi2Table* chi2)
      : Updater(context), camera_(camera), sigma2_(sigma2), chi2_(chi2) {}
  const char* name() const override { return "msckf"; }

  /// The stacked rows (H: rows × state dimension) of the tracks `ids` that
  /// triangulate with enough parallax (or, with msckf_rotation_rows, give
  /// rotation rows without it) and pass the gate, in the order of `ids`;
  /// outcomes are counted in the stats. Every track in `ids` is
  /// emptied (used or unusable: never twice).
  UpdateRows residuals(const std::vector<FeatureId>& ids, TrackMap* tracks);
  /// Features used by the last residuals() call.
  int lastCount() const { return last_count_; }
  /// The rows of the tracks the last residuals() call used, triangulated
  /// again and linearised at x (an iterate of the update; the same rows as
  /// residuals() at the state it saw). A track that no longer triangulates
  /// at x gives no rows.
  UpdateRows relinearize(const FilterState& x) const;

 private:
  Camera camera_;
  double sigma2_;
  const Chi2Table* chi2_;
  int last_count_ = 0;
  struct UsedTrack {
    FeatureTrack track;
    bool rotation = false;  // rotation rows (msckf_rotation_rows), else triangulated
  };
  std::vector<UsedTrack> used_;  // copies of the tracks the last residuals() used
};

}  // namespace evio::estimator

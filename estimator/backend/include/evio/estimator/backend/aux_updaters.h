#pragma once
/// @file aux_updaters.h
/// The updaters besides the visual ones (updater.h): the laser range finder
/// (range_update.h: range to the plane through three SLAM features) and the
/// zero-velocity pseudo-measurement.

#include <optional>
#include <utility>

#include "evio/core/sensor_rig.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/updater.h"

namespace evio::estimator {

class RangeUpdater : public Updater {
 public:
  RangeUpdater(const UpdaterContext& context, const RangeFinderSensor& sensor, const Chi2Table* chi2)
      : Updater(context), sensor_(sensor), chi2_(chi2) {}
  const char* name() const override { return "range"; }

  /// One reading at the filter time: the beam's hit point is kept for depth
  /// priors, then the range residual is gated (1 dof) and applied. False only
  /// when the EKF update failed (the backend then diverges); rejected readings
  /// are counted in the stats.
  bool update(double range_m);

  /// The latest reading's beam hit point h = o + range · d in W and its filter time.
  const std::optional<std::pair<TimeNs, Vec3>>& latestHit() const { return hit_; }

 private:
  RangeFinderSensor sensor_;
  const Chi2Table* chi2_;
  std::optional<std::pair<TimeNs, Vec3>> hit_;
};

class ZeroVelocityUpdater : public Updater {
 public:
  using Updater::Updater;
  const char* name() const override { return "zero_velocity"; }
  /// v_W = 0 with σ = zero_velocity_sigma_mps: r = −v̂, H = [0 I 0 0 0 | 0].
  /// False when the EKF update failed.
  bool update();
};

}  // namespace evio::estimator

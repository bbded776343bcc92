#pragma once
/// @file updater.h
/// The interface every measurement updater of the backend stands on
/// (docs/algorithms.md#ekf-backend): one kind of measurement per subclass —
/// MsckfUpdater (msckf_updater.h), SlamUpdater (slam_updater.h),
/// RangeUpdater and ZeroVelocityUpdater (aux_updaters.h) — each turning its
/// measurements into residual rows r ≈ H δx + n, n ~ N(0, σ² I), through the
/// services below, so that the observability constraint, the χ² gate and the
/// EKF update are written once.

#include "evio/core/camera/camera.h"
#include "evio/core/eigen_types.h"
#include "evio/core/error.h"
#include "evio/estimator/backend/backend_options.h"
#include "evio/estimator/backend/backend_status.h"
#include "evio/estimator/backend/filter_state.h"
#include "evio/estimator/backend/scene_depth.h"
#include "evio/estimator/backend/triangulation.h"
#include "evio/estimator/measurements.h"

namespace evio::estimator {

/// The backend's parts an updater works on (all owned by the backend).
struct UpdaterContext {
  FilterState* state = nullptr;
  /// The IMU state before the updates at the filter time: where the
  /// unobservable yaw direction is evaluated (first-estimate Jacobians).
  const ImuState* fej_imu = nullptr;
  const BackendOptions* options = nullptr;
  BackendStats* stats = nullptr;
  /// The innovations of the visual update under way (measurements.h).
  InnovationStats* innovation = nullptr;
  /// The latest triangulated points (scene_depth.h): MSCKF and SLAM
  /// triangulations add theirs, the depth prior from the map reads them.
  TriangulatedPoints* triangulated = nullptr;
  /// The filter time of the backend's initialisation.
  const TimeNs* initialized_at = nullptr;
};

/// Residual rows of a stacked update.
struct UpdateRows {
  MatX H;  ///< rows × state dimension
  VecX r;  ///< rows
};

class Updater {
 public:
  explicit Updater(const UpdaterContext& context) : ctx_(context) {}
  virtual ~Updater() = default;
  Updater(const Updater&) = delete;
  Updater& operator=(const Updater&) = delete;

  /// Short name of the measurement kind ("msckf", "slam", "range", "zero_velocity").
  virtual const char* name() const = 0;

  /// The observability constraint (when enabled): H ← H (I − n nᵀ/‖n‖²), the
  /// smallest change of H with H n = 0, n the yaw direction
  /// (FilterState::yawDirection at the first estimate).
  void constrain(MatX* H) const { constrainAt(state(), H); }
  /// The same for rows whose columns are those of another state `x` (e.g. the
  /// state with a feature about to be added): n is x's yaw direction.
  void constrainAt(const FilterState& x, MatX* H) const;

 protected:
  /// The Mahalanobis test rᵀ (H P Hᵀ + σ² I)⁻¹ r ≤ threshold (a χ² quantile).
  bool passesGate(const MatX& H, const VecX& r, double sigma2, double threshold) const;
  /// The same test, with the statistic recorded in the context's innovation
  /// stats (visual updates: self-diagnosis).
  bool passesRecordedGate(const MatX& H, const VecX& r, double sigma2, double threshold) const;
  /// Constrains H, then the EKF update (ekf_update.h); false when the
  /// innovation covariance is not positive definite (state unchanged).
  bool constrainAndUpdate(MatX H, const VecX& r, double sigma2) const;

  /// The triangulation settings of the options (MSCKF features and SLAM initialisation).
  /// The triangulation settings; for the information test (knowsDepth,
  /// when triangulate_when_better_than_prior) sigma_z, the σ of one
  /// normalised image coordinate, and prior_sigma_rho, the σ of the inverse-
  /// depth prior the triangulation has to beat, 1/m.
  TriangulationOptions triangulationOptions(double sigma_z, double prior_sigma_rho) const;
  /// σ_ρ0 = 1/(4 d_min) of the fixed depth prior, 1/m.
  double fixedDepthPriorSigma() const { return 1.0 / (4.0 * options().slam_min_depth_m); }
  /// ρ0 = 1/(2 d_min), the fixed depth prior's inverse depth, 1/m.
  double fixedDepthPriorRho() const { return 1.0 / (2.0 * options().slam_min_depth_m); }
  /// A parallax in px in normalised units: divided by the mean focal length of `camera`.
  double minParallaxNormalized(const Camera& camera, double parallax_px) const;

  FilterState& state() const { return *ctx_.state; }
  TimeNs initializedAt() const {
    require(ctx_.initialized_at != nullptr, "Updater: no initialisation time in the context");
    return *ctx_.initialized_at;
  }
  const BackendOptions& options() const { return *ctx_.options; }
  BackendStats& stats() const { return *ctx_.stats; }
  TriangulatedPoints& triangulatedPoints() const {
    require(ctx_.triangulated != nullptr, "Updater: the context has no triangulated-point memory");
    return *ctx_.triangulated;
  }

 private:
  UpdaterContext ctx_;
};

}  // namespace evio::estimator

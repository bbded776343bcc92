#pragma once
/// @file slam_updater.h
/// SLAM features in anchored inverse depth (updater.h; the models:
/// slam_features.h): the Mahalanobis gate on their observations, the rows
/// they give the stacked (iterated) update, their marginalisation when lost
/// or gated out too often, and the initialisation of new ones from a
/// triangulated track, a range-finder depth prior or the fixed depth prior.

#include <cstddef>
#include <optional>
#include <vector>

#include "evio/estimator/backend/aux_updaters.h"
#include "evio/estimator/backend/chi_squared.h"
#include "evio/estimator/backend/feature_selection.h"
#include "evio/estimator/backend/updater.h"

namespace evio::estimator {

/// The SLAM observations of one measurement set after the gate.
struct SlamGate {
  std::vector<FeatureObservation> accepted;  ///< go into the stacked update
  std::vector<std::size_t> gated_out;        ///< positions in state.features of features to drop
};

class SlamUpdater : public Updater {
 public:
  /// sigma_z: σ of one normalised image coordinate; slam_chi2 gates the
  /// observations, msckf_chi2 the triangulated initialisation; `range`
  /// (may be null) gives the latest range reading for depth priors.
  SlamUpdater(const UpdaterContext& context, const Camera& camera, double sigma_z, const Chi2Table* slam_chi2,
              const Chi2Table* msckf_chi2, const RangeUpdater* range)
      : Updater(context), camera_(camera), sigma_z_(sigma_z), slam_chi2_(slam_chi2), msckf_chi2_(msckf_chi2),
        range_(range) {}
  const char* name() const override { return "slam"; }

  /// Track drift (BackendOptions::slam_bearing_walk_px2_per_s): the bearing
  /// (α, β) of every SLAM feature gains q Δt / f² of variance, dt_s the time
  /// since the previous measurement set.
  void diffuseBearings(double dt_s);
  /// Track-error states over dt (slam_features.h decayTrackErrors).
  void decayTrackErrors(double dt_s);
  /// The scene's inverse depth ρ_s (BackendOptions::slam_scene_depth_share)
  /// random-walks: P_ss += c σ_ρ0² dt_s / slam_scene_depth_memory_s.
  void diffuseSceneDepth(double dt_s);
  /// Marginalises the SLAM features that the observations do not contain (lost tracks).
  void marginalizeUnobserved(const std::vector<FeatureObservation>& observations);
  /// The observations of SLAM features in clone c (position), each gated with
  /// 2 dof; a feature failing slam_max_gate_failures times in a row is gated out.
  /// With slam_update_interval_s (and/or slam_update_min_displacement_normalized),
  /// an observation of a feature updated less than that long before (that
  /// has moved less than that far since) is left out (neither accepted nor gated).
  /// With an error time constant τ stated by the tracker (FeatureObservation::
  /// error_time_s, from TrackPoint::error_time_s), the gate tests each observation
  /// with its own covariance, and an accepted one carries that covariance
  /// multiplied by coth(Δt / 2τ) into the update, Δt the time since the
  /// feature's last update (correlatedSampleVarianceFactor).
  SlamGate gate(const std::vector<FeatureObservation>& observations, std::size_t c);
  /// Rows of `accepted` at the linearisation point x (the iterated update
  /// calls it once per iteration), constrained; a feature missing from x or
  /// behind the clone gives zero rows.
  void relinearize(const FilterState& x, const std::vector<FeatureObservation>& accepted, std::size_t c, MatX* H,
                   VecX* r) const;
  /// Drops the gated-out features and any with non-finite parameters.
  void prune(std::vector<std::size_t> gated_out);
  /// New SLAM features from `candidates` (taken out of `tracks`) while slots
  /// are free. False when a triangulated initialisation's update failed.
  bool initialize(const std::vector<FeatureId>& candidates, TrackMap* tracks);

 private:
  /// The inverse-depth prior a new feature observed at z in clone c takes:
  /// from the range finder when it gives one, else from the map
  /// (depth_prior_from_map) when it knows the scene's depth, else the fixed prior.
  struct DepthPrior {
    enum class Source { kFixed, kRange, kMap };
    double rho = 0.0;    ///< 1/m
    double sigma = 0.0;  ///< 1/m
    Source source = Source::kFixed;
  };
  DepthPrior depthPrior(std::size_t c, const Vec2& z) const;
  /// Triangulated initialisation when the track fixes ρ better than the
  /// prior it would otherwise take (prior_sigma_rho, 1/m).
  bool initializeTriangulated(const FeatureTrack& track, double prior_sigma_rho, bool* done);
  void initializeWithPrior(const FeatureTrack& track, std::size_t c, const DepthPrior& prior);
  /// With slam_prior_init_with_track: the track's observations in the window
  /// and the depth prior together (refineWithDepthPrior, then the split of
  /// addSlamFeatureTriangulated with the prior as one more row), or with
  /// slam_prior_track_update initializeWithTrackUpdate. kNotUsed (the caller
  /// takes the plain prior) when the option is off, the track has one
  /// observation, the refinement fails or the rest fails its gate.
  enum class PriorWithTrack { kDone, kNotUsed, kUpdateFailed };
  PriorWithTrack initializeWithPriorAndTrack(const FeatureTrack& track, const DepthPrior& prior);
  /// slam_prior_track_update: the plain prior at the track's last
  /// observation, then the earlier observations as an update of clones and
  /// feature together, iterated slam_prior_track_iterations times, on a
  /// copy of the state (χ²-gated first; never kUpdateFailed: any failure,
  /// including an observation that cannot be predicted, is kNotUsed).
  PriorWithTrack initializeWithTrackUpdate(const FeatureTrack& track, const DepthPrior& prior,
                                             const std::vector<std::size_t>& positions, const std::vector<Vec2>& z,
                                             const std::vector<Mat2>& whiten);
  /// The fixed prior through the scene depth ρ_s (added to the state at the
  /// first call) when slam_scene_depth_share > 0 and ρ_s is positive.
  bool initializeFromSceneDepth(const FeatureTrack& track, std::size_t c, const DepthPrior& fixed);
  /// Once, when the triangulated points first give the scene's depth seen
  /// from clone c: ρ_s updated with their median inverse depth ρ_map as a
  /// measurement of σ ρ_map/2, which moves every feature that took the fixed
  /// prior through its correlation with ρ_s.
  void measureSceneDepth(std::size_t c);
  /// The fixed prior may be taken: slam_fixed_prior_wait_s has passed since
  /// the filter's initialisation.
  bool fixedPriorAllowed() const;
  /// ρ0 of a feature seen at normalised z from `clone`, from the latest range
  /// reading (BackendOptions::range_prior_relative_sigma); nullopt when there
  /// is none or the ray does not meet the level plane in front of the camera.
  std::optional<double> rangeDepthPrior(const CameraClone& clone, const Vec2& z) const;
  void removeFeature(std::size_t j);
  /// The feature's observation z at t_ns may enter the update
  /// (slam_update_interval_s, slam_update_min_displacement_normalized).
  bool dueForUpdate(const SlamFeature& f, TimeNs t_ns, const Vec2& z) const;

  Camera camera_;
  double sigma_z_;
  const Chi2Table* slam_chi2_;
  const Chi2Table* msckf_chi2_;
  const RangeUpdater* range_;
};

}  // namespace evio::estimator

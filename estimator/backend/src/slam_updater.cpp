#include "evio/estimator/backend/slam_updater.h"

#include <algorithm>
#include <cmath>
#include <unordered_set>

#include "evio/estimator/backend/ekf_update.h"
#include "evio/estimator/backend/msckf_update.h"
#include "evio/estimator/backend/range_update.h"
#include "evio/estimator/backend/slam_features.h"

namespace evio::estimator {

void SlamUpdater::removeFeature(std::size_t j) {
  state().removeFeature(j);
  ++stats().slam_features_removed;
}

void SlamUpdater::diffuseBearings(double dt_s) {
  const double q = options().slam_bearing_walk_px2_per_s;
  if (!(q > 0.0) || !(dt_s > 0.0)) return;
  const Vec4 k = camera_.intrinsics();  // fx fy cx cy: α = x/f_x, β = y/f_y in normalised units
  const double var_alpha = q * dt_s / (k(0) * k(0));
  const double var_beta = q * dt_s / (k(1) * k(1));
  for (std::size_t j = 0; j < state().features.size(); ++j) {
    const int i = state().featureIndex(j);
    state().P(i, i) += var_alpha;
    state().P(i + 1, i + 1) += var_beta;
  }
}

void SlamUpdater::decayTrackErrors(double dt_s) {
  estimator::decayTrackErrors(state(), dt_s, options().slam_track_error_time_s);
}

void SlamUpdater::diffuseSceneDepth(double dt_s) {
  if (!state().has_scene_depth || !(dt_s > 0.0)) return;
  const double sigma0 = fixedDepthPriorSigma();
  const int s = state().sceneDepthIndex();
  state().P(s, s) += options().slam_scene_depth_share * sigma0 * sigma0 * dt_s / options().slam_scene_depth_memory_s;
}

bool SlamUpdater::dueForUpdate(const SlamFeature& f, TimeNs t_ns, const Vec2& z) const {
  const double interval = options().slam_update_interval_s;
  const double displacement = options().slam_update_min_displacement_normalized;
  if (interval <= 0.0 && displacement <= 0.0) return true;  // every measurement set
  const bool waited = interval > 0.0 && nsToSeconds(t_ns - f.last_update_ns) >= interval - 1e-9;
  const bool moved = displacement > 0.0 && (z - f.last_update_z).norm() >= displacement;
  return waited || moved;
}

void SlamUpdater::marginalizeUnobserved(const std::vector<FeatureObservation>& observations) {
  std::unordered_set<FeatureId> observed;
  for (const FeatureObservation& o : observations) observed.insert(o.id);
  for (std::size_t j = state().features.size(); j-- > 0;)
    if (observed.count(state().features[j].id) == 0) removeFeature(j);
}

SlamGate SlamUpdater::gate(const std::vector<FeatureObservation>& observations, std::size_t c) {
  SlamGate out;
  const double sigma2 = sigma_z_ * sigma_z_;
  for (const FeatureObservation& o : observations) {
    if (!o.informative) continue;  // alive (marginalizeUnobserved saw it), not observed
    const int j = state().findFeature(o.id);
    if (j < 0) continue;
    const auto jj = static_cast<std::size_t>(j);
    if (!dueForUpdate(state().features[jj], state().clones[c].t_ns, o.z)) continue;
    const double kappa = correlatedSampleVarianceFactor(
        nsToSeconds(state().clones[c].t_ns - state().features[jj].last_update_ns),
        o.error_time_s);
    if (!std::isfinite(kappa)) continue;  // observed in the clone of its last update: nothing new
    Eigen::Matrix<double, 2, Eigen::Dynamic> H;
    Vec2 r;
    MatX Hc;
    FeatureObservation obs = o;
    Mat2 second_order;
    if (options().slam_second_order_noise && slamSecondOrderCovariance(state(), jj, c, &second_order))
      obs.whiten = whitenWithExtraCovariance(o.whiten, sigma_z_, second_order);
    const bool ok = slamResidual(state(), jj, c, o.z, &H, &r);
    if (ok) {
      H = obs.whiten * H;  // whitened to σ_z² I (feature_track.h)
      r = obs.whiten * r;
      Hc = H;
      constrain(&Hc);
    }
    SlamFeature& f = state().features[jj];
    if (!ok || !passesRecordedGate(Hc, r, sigma2, (*slam_chi2_)(2))) {
      ++stats().slam_updates_rejected;
      if (++f.gate_failures >= options().slam_max_gate_failures) out.gated_out.push_back(jj);
      continue;
    }
    f.gate_failures = 0;
    f.last_update_ns = state().clones[c].t_ns;
    f.last_update_z = o.z;
    // The gate tests one observation against its own (marginal) covariance;
    // the update takes it as one of a run of correlated samples, its
    // covariance × κ (1 for a tracker that states no error time constant: the gate's W).
    obs.whiten /= std::sqrt(kappa);
    out.accepted.push_back(obs);
  }
  return out;
}

void SlamUpdater::relinearize(const FilterState& x, const std::vector<FeatureObservation>& accepted, std::size_t c,
                              MatX* H, VecX* r) const {
  const auto rows = 2 * static_cast<Eigen::Index>(accepted.size());
  H->setZero(rows, x.dim());
  r->setZero(rows);
  for (std::size_t q = 0; q < accepted.size(); ++q) {
    Eigen::Matrix<double, 2, Eigen::Dynamic> Hq;
    Vec2 rq;
    const int j = x.findFeature(accepted[q].id);
    if (j < 0 || !slamResidual(x, static_cast<std::size_t>(j), c, accepted[q].z, &Hq, &rq)) continue;
    H->middleRows<2>(2 * static_cast<Eigen::Index>(q)) = accepted[q].whiten * Hq;
    r->segment<2>(2 * static_cast<Eigen::Index>(q)) = accepted[q].whiten * rq;
  }
  constrain(H);
}

void SlamUpdater::prune(std::vector<std::size_t> gated_out) {
  std::sort(gated_out.begin(), gated_out.end());
  for (std::size_t q = gated_out.size(); q-- > 0;) removeFeature(gated_out[q]);
  for (std::size_t j = state().features.size(); j-- > 0;)
    if (!state().features[j].abr.allFinite() || !state().features[j].track_error.allFinite()) removeFeature(j);
}

bool SlamUpdater::initialize(const std::vector<FeatureId>& candidates, TrackMap* tracks) {
  const std::size_t c = state().clones.size() - 1;
  if (state().has_scene_depth && !state().scene_depth_measured) measureSceneDepth(c);
  for (const FeatureId id : candidates) {
    if (static_cast<int>(state().features.size()) >= options().max_slam_features) break;
    auto it = tracks->find(id);
    if (it == tracks->end() || it->second.observations.empty()) continue;
    const FeatureTrack& track = it->second;  // initialising touches the state, not the tracks
    const DepthPrior prior = depthPrior(c, track.observations.back().z);
    const std::size_t features_before = state().features.size();
    bool done = false;
    if (options().slam_triangulated_init && !initializeTriangulated(track, prior.sigma, &done)) {
      tracks->erase(it);
      return false;
    }
    if (!done) {
      if (prior.source == DepthPrior::Source::kFixed && !fixedPriorAllowed()) {
        ++stats().slam_waiting_for_depth;  // stays in the window until the scene's depth is known
        continue;
      }
      const PriorWithTrack with_track = initializeWithPriorAndTrack(track, prior);
      if (with_track == PriorWithTrack::kUpdateFailed) {
        tracks->erase(it);
        return false;
      }
      if (with_track == PriorWithTrack::kNotUsed) initializeWithPrior(track, c, prior);
    }
    // Every initialisation takes the track's observation in clone c (its last).
    if (state().features.size() > features_before) {
      state().features.back().last_update_ns = state().clones[c].t_ns;
      state().features.back().last_update_z = track.observations.back().z;
    }
    tracks->erase(it);  // the track is a SLAM feature now, or failed its gate
  }
  return true;
}

bool SlamUpdater::initializeTriangulated(const FeatureTrack& track, double prior_sigma_rho, bool* done) {
  std::vector<CameraClone> clones;
  std::vector<std::size_t> positions;
  std::vector<Vec2> z;
  gatherTrack(state(), track, &clones, &positions, &z);
  const TriangulationOptions tri = triangulationOptions(sigma_z_, prior_sigma_rho);
  const double min_parallax = minParallaxNormalized(camera_, options().slam_min_parallax_px);
  TriangulationResult res;
  if (clones.size() < 2 || rotationCompensatedDisparity(clones, z) < min_parallax ||
      !triangulateFeature(clones, z, clones.size() - 1, tri, &res) || !knowsDepth(res, tri))
    return true;
  const SlamInitOutcome outcome =
      addSlamFeatureTriangulated(state(), track, res.abr, sigma_z_ * sigma_z_, options().joseph_form, *msckf_chi2_,
                                 [this](MatX* H) { constrain(H); });
  if (outcome == SlamInitOutcome::kUpdateFailed) return false;
  *done = outcome == SlamInitOutcome::kOk;
  if (!*done) return true;
  ++stats().slam_initialized_triangulated;
  const CameraClone& anchor = clones.back();  // the triangulation's anchor: the track's last clone
  triangulatedPoints().add(anchor.p_W_C + anchor.R_W_C() * Vec3(res.abr.x(), res.abr.y(), 1.0) / res.abr.z());
  return true;
}

SlamUpdater::PriorWithTrack SlamUpdater::initializeWithPriorAndTrack(const FeatureTrack& track,
                                                                      const DepthPrior& prior) {
  if (!options().slam_prior_init_with_track) return PriorWithTrack::kNotUsed;
  std::vector<CameraClone> clones;
  std::vector<std::size_t> positions;
  std::vector<Vec2> z;
  std::vector<Mat2> whiten;
  gatherTrack(state(), track, &clones, &positions, &z, &whiten);
  if (clones.size() < 2 || rotationCompensatedDisparity(clones, z) <
                                minParallaxNormalized(camera_, options().slam_prior_track_min_parallax_px))
    return PriorWithTrack::kNotUsed;
  if (options().slam_prior_track_update) return initializeWithTrackUpdate(track, prior, positions, z, whiten);
  const TriangulationOptions tri = triangulationOptions(sigma_z_, prior.sigma);
  Vec3 abr;
  if (!refineWithDepthPrior(clones, z, whiten, clones.size() - 1, prior.rho, prior.sigma, sigma_z_, tri, &abr))
    return PriorWithTrack::kNotUsed;
  const InverseDepthPrior row{prior.rho, prior.sigma};
  const SlamInitOutcome outcome =
      addSlamFeatureTriangulated(state(), track, abr, sigma_z_ * sigma_z_, options().joseph_form, *msckf_chi2_,
                                 [this](MatX* H) { constrain(H); }, &row);
  if (outcome == SlamInitOutcome::kUpdateFailed) return PriorWithTrack::kUpdateFailed;
  if (outcome != SlamInitOutcome::kOk) return PriorWithTrack::kNotUsed;
  ++stats().slam_initialized_prior_track;
  return PriorWithTrack::kDone;
}

SlamUpdater::PriorWithTrack SlamUpdater::initializeWithTrackUpdate(const FeatureTrack& track,
                                                                    const DepthPrior& prior,
                                                                    const std::vector<std::size_t>& positions,
                                                                    const std::vector<Vec2>& z,
                                                                    const std::vector<Mat2>& whiten) {
  // The plain prior at the last observation (its clone the anchor): (α, β)
  // from that observation, ρ from the prior, on a copy of the state.
  FilterState x = state();
  addSlamFeatureWithPrior(x, track.id, positions.back(), z.back(), prior.rho, prior.sigma, sigma_z_, whiten.back());
  // The earlier observations: whitened rows r_k = W_k (z_k − h(clone_k, f)),
  // re-linearised at every iterate of clones and feature. An observation
  // that cannot be predicted (the point behind its clone) at any iterate
  // leaves the plain prior alone.
  const std::size_t earlier = positions.size() - 1;
  bool all_rows = true;
  const auto rows = [&](const FilterState& at, MatX* H, VecX* r) {
    H->setZero(2 * static_cast<Eigen::Index>(earlier), at.dim());
    r->setZero(2 * static_cast<Eigen::Index>(earlier));
    const int j = at.findFeature(track.id);
    for (std::size_t k = 0; k < earlier; ++k) {
      Eigen::Matrix<double, 2, Eigen::Dynamic> Hk;
      Vec2 rk;
      if (j < 0 || !slamResidual(at, static_cast<std::size_t>(j), positions[k], z[k], &Hk, &rk)) {
        all_rows = false;
        continue;
      }
      H->middleRows<2>(2 * static_cast<Eigen::Index>(k)) = whiten[k] * Hk;
      r->segment<2>(2 * static_cast<Eigen::Index>(k)) = whiten[k] * rk;
    }
    constrainAt(at, H);
  };
  const double sigma2 = sigma_z_ * sigma_z_;
  MatX H;
  VecX r;
  rows(x, &H, &r);
  // The same χ² gate as the triangulated initialisation's remaining rows.
  if (!all_rows || mahalanobisSquared(H, r, x.P, sigma2) > (*msckf_chi2_)(static_cast<int>(r.size())))
    return PriorWithTrack::kNotUsed;
  // Only the copy is touched: a failed update, a lost row or a point ending
  // behind its anchor leave the plain prior.
  if (!iteratedEkfUpdate(x, rows, MatX(), VecX(), sigma2, options().slam_prior_track_iterations,
                         options().joseph_form) ||
      !all_rows)
    return PriorWithTrack::kNotUsed;
  const int j = x.findFeature(track.id);
  if (j < 0 || !x.features[static_cast<std::size_t>(j)].abr.allFinite() ||
      !(x.features[static_cast<std::size_t>(j)].abr.z() > 0.0))
    return PriorWithTrack::kNotUsed;
  state() = std::move(x);
  ++stats().slam_initialized_prior_track;
  return PriorWithTrack::kDone;
}

bool SlamUpdater::fixedPriorAllowed() const {
  const double wait_s = options().slam_fixed_prior_wait_s;
  return wait_s <= 0.0 || nsToSeconds(state().imu.t_ns - initializedAt()) >= wait_s;
}

SlamUpdater::DepthPrior SlamUpdater::depthPrior(std::size_t c, const Vec2& z) const {
  if (const auto rho = rangeDepthPrior(state().clones[c], z))
    return {*rho, options().range_prior_relative_sigma * *rho, DepthPrior::Source::kRange};
  // The fixed prior: ρ0 = 1/(2 d_min), σ_ρ0 = 1/(4 d_min), i.e. σ_ρ0 = ρ0 / 2.
  const DepthPrior fixed{fixedDepthPriorRho(), fixedDepthPriorSigma(), DepthPrior::Source::kFixed};
  if (!options().depth_prior_from_map) return fixed;
  // The same shape centred on the median inverse depth of what the filter triangulated.
  std::vector<Vec3> points = convergedSlamPoints(state(), options().map_prior_max_relative_sigma);
  const std::vector<Vec3>& recent = triangulatedPoints().points();
  points.insert(points.end(), recent.begin(), recent.end());
  const auto rho = medianInverseDepth(state().clones[c], points, options().map_prior_min_points);
  if (!rho) return fixed;
  return {*rho, 0.5 * *rho, DepthPrior::Source::kMap};
}

void SlamUpdater::initializeWithPrior(const FeatureTrack& track, std::size_t c, const DepthPrior& prior) {
  const Vec2& z = track.observations.back().z;
  const Mat2& W = track.observations.back().whiten;
  if (prior.source == DepthPrior::Source::kFixed && initializeFromSceneDepth(track, c, prior)) {
    ++stats().slam_initialized_prior;
    return;
  }
  addSlamFeatureWithPrior(state(), track.id, c, z, prior.rho, prior.sigma, sigma_z_, W);
  switch (prior.source) {
    case DepthPrior::Source::kRange: ++stats().slam_initialized_range; break;
    case DepthPrior::Source::kMap: ++stats().slam_initialized_map; break;
    case DepthPrior::Source::kFixed: ++stats().slam_initialized_prior; break;
  }
}

void SlamUpdater::measureSceneDepth(std::size_t c) {
  // Only the triangulated points (MSCKF features, not in the state, and
  // triangulated SLAM initialisations, which never took the prior): the SLAM
  // features that converged may be the fixed-prior ones themselves.
  const auto rho = medianInverseDepth(state().clones[c], triangulatedPoints().points(), options().map_prior_min_points);
  if (!rho) return;
  // ρ_map = ρ_s + v, v ~ N(0, (ρ_map/2)²): the map prior's σ for one feature.
  MatX H = MatX::Zero(1, state().dim());
  H(0, state().sceneDepthIndex()) = 1.0;
  VecX r(1);
  r(0) = *rho - state().scene_rho;
  if (!ekfUpdate(state(), H, r, 0.25 * *rho * *rho, options().joseph_form)) return;
  state().scene_depth_measured = true;
  ++stats().slam_scene_depth_measured;
}

bool SlamUpdater::initializeFromSceneDepth(const FeatureTrack& track, std::size_t c, const DepthPrior& fixed) {
  const double share = options().slam_scene_depth_share;
  if (!(share > 0.0)) return false;
  // The fixed prior's variance split: c σ² shared (ρ_s), (1 − c) σ² the feature's own.
  if (!state().has_scene_depth) state().addSceneDepth(fixed.rho, share * fixed.sigma * fixed.sigma);
  if (!(state().scene_rho > 0.0)) return false;  // a scene behind the camera: the plain prior
  const TrackObservation& last = track.observations.back();
  addSlamFeatureFromSceneDepth(state(), track.id, c, last.z, std::sqrt(1.0 - share) * fixed.sigma, sigma_z_,
                               last.whiten);
  return true;
}

std::optional<double> SlamUpdater::rangeDepthPrior(const CameraClone& clone, const Vec2& z) const {
  if (!options().use_range || !(options().range_prior_relative_sigma > 0.0) || !range_ || !range_->latestHit())
    return std::nullopt;
  const auto& hit = *range_->latestHit();
  if (nsToSeconds(clone.t_ns - hit.first) > options().range_prior_max_age_s) return std::nullopt;
  return inverseDepthOnLevelPlane(clone, z, hit.second.z(), options().triangulation_min_depth_m);
}

}  // namespace evio::estimator
